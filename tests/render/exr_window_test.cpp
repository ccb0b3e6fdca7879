// EXR data windows and header attributes: a cropped render written with its crop as the
// data window inside the full display window, read back by OpenEXR itself, by
// read_exr_image (every channel in its own type) and by compare's read_image; M44f,
// Rational and opaque attributes; the camera matrices against the camera's own rays.

#include <ImfChannelList.h>
#include <ImfChromaticitiesAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfVecAttribute.h>
#include <gtest/gtest.h>
#include <half.h>

#include <cmath>

#include "output_fixtures.h"
#include "render/batch/camera_matrices.h"
#include "render/image/image_io.h"
#include "render/image/image_read.h"
#include "scene_builders.h"

namespace octray {
namespace {

TEST(ExrWindows, CroppedRenderRoundTrips) {
    const std::filesystem::path dir = testing::test_dir();
    const Scene scene = testing::golden_scene("pinhole_checker", 40, 30);
    RenderOptions options;
    options.crop = PixelRect{7, 5, 29, 26};
    const RenderResult result = render_packet(scene, options);
    for (bool float32 : {false, true}) {
        SCOPED_TRACE(float32 ? "float" : "half");
        const std::string path = (dir / "crop.exr").string();
        write_exr(path,
                  make_exr_image(result.image, ExrWriteOptions{float32, ExrCompression::piz}));

        // OpenEXR's own view: inclusive boxes.
        Imf::InputFile file(path.c_str());
        const Imath::Box2i data = file.header().dataWindow();
        const Imath::Box2i display = file.header().displayWindow();
        EXPECT_EQ(data.min, Imath::V2i(7, 5));
        EXPECT_EQ(data.max, Imath::V2i(28, 25));
        EXPECT_EQ(display.min, Imath::V2i(0, 0));
        EXPECT_EQ(display.max, Imath::V2i(39, 29));
        EXPECT_EQ(file.header().compression(), Imf::PIZ_COMPRESSION);

        const Image back = read_exr_image(path);
        EXPECT_EQ(back.data_window, *options.crop);
        EXPECT_EQ(back.display_window, (PixelRect{0, 0, 40, 30}));
        EXPECT_EQ(back.compression, ExrCompression::piz);
        ASSERT_EQ(back.channels.size(), 3u);
        const ImageChannel* g = back.find_channel("G");
        ASSERT_NE(g, nullptr);
        EXPECT_EQ(g->format, float32 ? PixelFormat::float32 : PixelFormat::half);
        ASSERT_EQ(g->size(), options.crop->pixel_count());
        for (int y = 0; y < 21; ++y)
            for (int x = 0; x < 22; ++x) {
                const float v = rgb_at(result.image, x, y).g;
                EXPECT_EQ(g->value(static_cast<std::size_t>(y) * 22 + x),
                          float32 ? v : float(half(v)));
            }
        // Written again unchanged: the same samples, byte for byte.
        const std::string again = (dir / "again.exr").string();
        write_exr(again, back);
        const Image twice = read_exr_image(again);
        EXPECT_EQ(twice.data_window, back.data_window);
        EXPECT_EQ(twice.channels.size(), back.channels.size());
        for (const ImageChannel& c : back.channels)
            EXPECT_EQ(twice.find_channel(c.name)->samples, c.samples) << c.name;

        // compare's reader keeps working and reports the data window's corner.
        const Image image = read_image(path);
        EXPECT_EQ(image.width(), 22);
        EXPECT_EQ(image.height(), 21);
        EXPECT_EQ(image.data_window.x0, 7);
        EXPECT_EQ(image.data_window.y0, 5);
    }
}

TEST(ExrWindows, WriterRefusesInconsistentImages) {
    const std::filesystem::path dir = testing::test_dir();
    const std::string path = (dir / "bad.exr").string();
    Image image(4, 3, {"R", "G", "B"});
    image.data_window = PixelRect{1, 1, 5, 4};
    image.display_window = PixelRect{0, 0, 8, 8};
    Image good = make_exr_image(image, ExrWriteOptions{});
    EXPECT_NO_THROW(write_exr(path, good));

    Image short_channel = good;
    short_channel.channels[1].samples.pop_back();
    EXPECT_THROW(write_exr(path, short_channel), IoError);
    Image twice = good;
    twice.channels.push_back(twice.channels[0]);
    EXPECT_THROW(write_exr(path, twice), IoError);
    Image structural = good;
    structural.attributes.ints.emplace_back("dataWindow", 3);
    EXPECT_THROW(write_exr(path, structural), IoError);
    Image duplicate = good;
    duplicate.attributes.ints.emplace_back("frame", 3);
    duplicate.attributes.floats.emplace_back("frame", 3.0f);
    EXPECT_THROW(write_exr(path, duplicate), IoError);
    Image empty = good;
    empty.data_window = PixelRect{2, 2, 2, 5};
    try {
        write_exr(path, empty);
        ADD_FAILURE() << "no exception";
    } catch (const IoError& e) {
        EXPECT_NE(std::string(e.what()).find("data window (2, 2)-(2, 5) is empty"),
                  std::string::npos)
            << e.what();
    }
    // Only a render's float32 channels are converted: `good` already holds half ones.
    EXPECT_THROW(make_exr_image(good, ExrWriteOptions{}), std::invalid_argument);
    // The failed writes left nothing behind but the good file.
    std::size_t files = 0;
    for ([[maybe_unused]] const auto& e : std::filesystem::directory_iterator(dir)) ++files;
    EXPECT_EQ(files, 1u);
}

TEST(ExrAttributes, MatricesRationalsAndOpaqueAttributesReadBack) {
    const std::filesystem::path dir = testing::test_dir();
    const std::string path = (dir / "attrs.exr").string();
    ExrAttributes attributes;
    Matrix44 m;
    for (std::size_t k = 0; k < 16; ++k) m[k] = static_cast<float>(k) + 0.5f;
    attributes.matrices.emplace_back("worldToCamera", m);
    attributes.rationals.emplace_back("framesPerSecond", exr_rational(24000.0 / 1001.0));
    attributes.strings.emplace_back("octray:scene", "whitted");
    attributes.ints.emplace_back("octray:frame", 12);
    write_exr(path, Image(3, 2, {"R", "G", "B"}), ExrWriteOptions{}, attributes);

    {
        Imf::InputFile file(path.c_str());
        ASSERT_TRUE(Imf::hasWorldToCamera(file.header()));
        const Imath::M44f& w = Imf::worldToCamera(file.header());
        EXPECT_EQ(w[0][0], 0.5f);
        EXPECT_EQ(w[0][3], 3.5f);  // row 0, column 3: element 3
        EXPECT_EQ(w[3][0], 12.5f);
        ASSERT_TRUE(Imf::hasFramesPerSecond(file.header()));
        EXPECT_EQ(Imf::framesPerSecond(file.header()).n, 24000);
        EXPECT_EQ(Imf::framesPerSecond(file.header()).d, 1001u);
    }
    EXPECT_EQ(exr_rational(24.0), (ExrRational{24, 1}));
    EXPECT_EQ(exr_rational(25.0), (ExrRational{25, 1}));

    const Image back = read_exr_image(path);
    ASSERT_EQ(back.attributes.matrices.size(), 1u);
    EXPECT_EQ(back.attributes.matrices[0].first, "worldToCamera");
    EXPECT_EQ(back.attributes.matrices[0].second, m);
    ASSERT_EQ(back.attributes.rationals.size(), 1u);
    EXPECT_EQ(back.attributes.rationals[0].second, (ExrRational{24000, 1001}));

    // A file with attributes octray does not interpret keeps them through a rewrite.
    const std::string foreign = (dir / "foreign.exr").string();
    {
        Imf::Header header(2, 2);
        header.insert("cameraOffset", Imf::V2fAttribute(Imath::V2f(0.25f, -2.0f)));
        Imf::addChromaticities(header, Imf::Chromaticities());
        header.channels().insert("Y", Imf::Channel(Imf::HALF));
        std::vector<half> y(4, half(0.5f));
        Imf::FrameBuffer fb;
        fb.insert("Y", Imf::Slice(Imf::HALF, reinterpret_cast<char*>(y.data()), sizeof(half),
                                  2 * sizeof(half)));
        Imf::OutputFile out(foreign.c_str(), header);
        out.setFrameBuffer(fb);
        out.writePixels(2);
    }
    const std::string rewritten = (dir / "rewritten.exr").string();
    write_exr(rewritten, read_exr_image(foreign));
    Imf::InputFile file(rewritten.c_str());
    const auto* offset = file.header().findTypedAttribute<Imf::V2fAttribute>("cameraOffset");
    ASSERT_NE(offset, nullptr);
    EXPECT_EQ(offset->value(), Imath::V2f(0.25f, -2.0f));
    ASSERT_TRUE(Imf::hasChromaticities(file.header()));
    EXPECT_EQ(Imf::chromaticities(file.header()).red, Imf::Chromaticities().red);
}

// Where the camera's own ray for pixel (i, j) at the pixel center goes, worldToNDC maps
// back to ((i + 0.5) / W, (j + 0.5) / H); worldToCamera puts the eye at the origin and
// the view down -Z.
void expect_matrices_match_rays(const Scene& scene) {
    const Matrix44 to_camera = batch::world_to_camera(scene);
    const std::optional<Matrix44> to_ndc = batch::world_to_ndc(scene);
    ASSERT_TRUE(to_ndc);
    const ReferenceTracer tracer(scene);
    const int w = scene.image.width, h = scene.image.height;
    for (const auto& [i, j] : std::vector<std::pair<int, int>>{
             {0, 0}, {w - 1, 0}, {5, 7}, {w / 2, h / 2}, {w - 1, h - 1}}) {
        const Ray ray = *tracer.camera_ray(i, j, 0);  // spp 1: the pixel center
        for (float t : {1.0f, 3.0f, 10.0f}) {
            const Vec3 p = ray.origin + ray.direction * t;
            const Vec3 ndc = batch::transform_point(*to_ndc, p);
            EXPECT_NEAR(ndc.x * w, i + 0.5f, 2e-3f) << i << "," << j << " t " << t;
            EXPECT_NEAR(ndc.y * h, j + 0.5f, 2e-3f) << i << "," << j << " t " << t;
            // In camera space the point lies in front of the eye (negative z).
            EXPECT_LT(batch::transform_point(to_camera, p).z, 0.0f);
        }
    }
    const Vec3 eye = batch::transform_point(to_camera, scene.camera.eye);
    EXPECT_NEAR(eye.x, 0.0f, 1e-5f);
    EXPECT_NEAR(eye.y, 0.0f, 1e-5f);
    EXPECT_NEAR(eye.z, 0.0f, 1e-5f);
    const Vec3 target = batch::transform_point(to_camera, scene.camera.lookat);
    EXPECT_NEAR(target.x, 0.0f, 1e-5f);
    EXPECT_NEAR(target.y, 0.0f, 1e-5f);
    EXPECT_NEAR(target.z, -length(scene.camera.lookat - scene.camera.eye), 1e-4f);
}

TEST(CameraMatrices, ProjectThePixelsOwnRays) {
    Scene pinhole = testing::golden_scene("pinhole_checker", 48, 30, 1);
    expect_matrices_match_rays(pinhole);
    Scene ortho = testing::golden_scene("orthographic", 30, 41, 1);
    expect_matrices_match_rays(ortho);
    Scene lens = testing::golden_scene("thinlens_spp4", 32, 20, 1);
    lens.camera.aperture = 0.0f;  // its in-focus projection: the lens center's rays
    expect_matrices_match_rays(lens);

    const Scene fisheye = testing::golden_scene("fisheye", 16, 16);
    EXPECT_FALSE(batch::world_to_ndc(fisheye));
    ExrAttributes attributes;
    batch::add_camera_attributes(attributes, fisheye, fisheye.camera);
    ASSERT_EQ(attributes.matrices.size(), 1u);
    EXPECT_EQ(attributes.matrices[0].first, "worldToCamera");
    batch::add_camera_attributes(attributes, pinhole, pinhole.camera);
    ASSERT_EQ(attributes.matrices.size(), 3u);
    EXPECT_EQ(attributes.matrices[2].first, "worldToNDC");
}

}  // namespace
}  // namespace octray
