#include "display/display.h"

#include <cmath>
#include <cstdint>

namespace candela {

DisplayRect fit_image_rect(int image_width, int image_height, const DisplayRect& area) {
    if (image_width <= 0 || image_height <= 0 || area.width <= 0 || area.height <= 0) return {area.x, area.y, 0, 0};
    // Compare aspect ratios in 64-bit integers: exact, so an area of the image's own shape maps
    // to itself without a rounding pixel lost.
    DisplayRect r;
    if (int64_t(area.width) * image_height <= int64_t(area.height) * image_width) {
        r.width = area.width;
        r.height = int(std::lround(double(area.width) * image_height / image_width));
    } else {
        r.height = area.height;
        r.width = int(std::lround(double(area.height) * image_width / image_height));
    }
    if (r.width < 1) r.width = 1;
    if (r.height < 1) r.height = 1;
    r.x = area.x + (area.width - r.width) / 2;
    r.y = area.y + (area.height - r.height) / 2;
    return r;
}

}  // namespace candela
