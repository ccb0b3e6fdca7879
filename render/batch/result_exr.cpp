#include "render/batch/result_exr.h"

#include <utility>

namespace octray {

ExrImage make_exr_image(const RenderResult& result, const ExrWriteOptions& options,
                        const ExrAttributes& attributes, std::vector<ExrChannel> spare) {
    return make_exr_image(result.image, result.rect, result.full_width, result.full_height,
                          options, attributes, std::move(spare));
}

}  // namespace octray
