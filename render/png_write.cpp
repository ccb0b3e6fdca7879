// write_png_rgb8(): declared in image_io.h, kept in its own file.

#include <png.h>

#include <cerrno>
#include <csetjmp>
#include <cstdio>
#include <cstring>
#include <string>
#include <system_error>
#include <vector>

#include "render/image_io.h"

namespace octray {
namespace {

// The message of a libpng error, with the OS reason (errno) of a failed write: libpng's
// own writer would say only "Write Error".
struct PngSinkError {
    char message[256] = {};
    std::FILE* file = nullptr;
    int write_errno = 0;
};

void on_png_error(png_structp png, png_const_charp message) {
    auto* error = static_cast<PngSinkError*>(png_get_error_ptr(png));
    if (error->write_errno != 0)
        std::snprintf(error->message, sizeof error->message, "%s: %s", message,
                      std::strerror(error->write_errno));
    else
        std::snprintf(error->message, sizeof error->message, "%s", message);
    png_longjmp(png, 1);
}

void on_png_write(png_structp png, png_bytep data, png_size_t length) {
    auto* error = static_cast<PngSinkError*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fwrite(data, 1, length, error->file) != length) {
        error->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

void on_png_flush(png_structp png) {
    auto* error = static_cast<PngSinkError*>(png_get_io_ptr(png));
    errno = 0;
    if (std::fflush(error->file) != 0) {
        error->write_errno = errno != 0 ? errno : EIO;
        png_error(png, "Write Error");
    }
}

void on_png_warning(png_structp, png_const_charp) {}

// libpng reports errors by longjmp back here; nothing with a destructor is created in this
// frame after setjmp, so the jump skips none.
bool write_rgb8_rows(png_structp png, png_infop info, PngSinkError* sink, png_uint_32 width,
                     png_uint_32 height, png_bytepp rows) {
    if (setjmp(png_jmpbuf(png))) return false;
    png_set_write_fn(png, sink, on_png_write, on_png_flush);
    png_set_IHDR(png, info, width, height, 8, PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE,
                 PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_sRGB(png, info, PNG_sRGB_INTENT_PERCEPTUAL);
    png_write_info(png, info);
    png_write_image(png, rows);
    png_write_end(png, nullptr);
    return true;
}

}  // namespace

void write_png_rgb8(const std::string& path, int width, int height,
                    const std::vector<std::uint8_t>& rgb) {
    if (width <= 0 || height <= 0 ||
        rgb.size() != 3 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height))
        throw IoError("cannot write '" + path + "': " + std::to_string(rgb.size()) +
                      " bytes do not make a " + std::to_string(width) + "x" +
                      std::to_string(height) + " RGB image");

    // libpng wants mutable row pointers but only reads through them.
    std::vector<png_bytep> rows(static_cast<std::size_t>(height));
    for (std::size_t y = 0; y < rows.size(); ++y)
        rows[y] = const_cast<png_bytep>(rgb.data() + y * 3 * static_cast<std::size_t>(width));

    write_file_atomically(path, [&](const std::string& tmp_path) {
        std::FILE* file = std::fopen(tmp_path.c_str(), "wb");
        if (!file) throw IoError(tmp_path + ": " + std::generic_category().message(errno));
        PngSinkError error;
        error.file = file;
        png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, &error, on_png_error,
                                                  on_png_warning);
        png_infop info = png ? png_create_info_struct(png) : nullptr;
        bool ok = png && info &&
                  write_rgb8_rows(png, info, &error, static_cast<png_uint_32>(width),
                                  static_cast<png_uint_32>(height), rows.data());
        png_destroy_write_struct(&png, info ? &info : nullptr);
        const int close_status = std::fclose(file);
        if (!ok)
            throw IoError(std::string("libpng: ") +
                          (error.message[0] ? error.message : "out of memory"));
        if (close_status != 0)
            throw IoError(tmp_path + ": " + std::generic_category().message(errno));
    });
}

}  // namespace octray
