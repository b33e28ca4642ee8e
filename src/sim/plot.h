// Drawing helpers of wavog_evaluate: a 3x5 pixel font, lines and filled boxes on wavog::Image.
// Private to src/sim and src/tools (not installed). Thread-safe (free functions on values).
#ifndef WAVOG_MAPPING_SRC_SIM_PLOT_H_
#define WAVOG_MAPPING_SRC_SIM_PLOT_H_

#include <string>

#include "wavog_mapping/io/image_io.h"

namespace wavog {
namespace sim {

/// Sets one pixel of an RGB image (ignored outside).
void putPixel(Image* image, int x, int y, Rgb colour);
/// Filled rectangle [x0, x1) x [y0, y1).
void fillRect(Image* image, int x0, int y0, int x1, int y1, Rgb colour);
/// Line from (x0, y0) to (x1, y1), `width` pixels thick; dashed if `dash` > 0 (pixels on/off).
void drawLine(Image* image, int x0, int y0, int x1, int y1, Rgb colour, int width = 1,
              int dash = 0);
/// Text with the top-left corner at (x, y), 3x5 glyphs magnified `scale` times; letters are
/// drawn as capitals. Returns the width drawn (pixels).
int drawText(Image* image, int x, int y, const std::string& text, Rgb colour, int scale = 2);
/// Width of `text` as drawText would draw it.
int textWidth(const std::string& text, int scale = 2);

}  // namespace sim
}  // namespace wavog

#endif  // WAVOG_MAPPING_SRC_SIM_PLOT_H_
