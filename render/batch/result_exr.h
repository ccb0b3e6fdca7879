#pragma once
// A render as an OpenEXR image: the bridge between the renderer's RenderResult and the
// image library (render/image/), which knows nothing of renders.

#include "render/image/image_io.h"
#include "render/types.h"

namespace octray {

// R, G, B channels (half, or float32 with options.float32) of a render: data window
// result.rect, display window the full image (0, 0)-(full_width, full_height).
// `spare`: a written frame's channels, whose storage the new ones take (image_io.h).
ExrImage make_exr_image(const RenderResult& result, const ExrWriteOptions& options,
                        const ExrAttributes& attributes = {},
                        std::vector<ExrChannel> spare = {});

}  // namespace octray
