// Pictures of normal-distribution cells (MapParams::ndt): the occupancy map of one scale, drawn as
// renderRgb draws it and upscaled so that a cell spans several pixels, with each Gaussian of
// WaveletMap::exportNdt as the outline of its 2-sigma ellipse and a dot at its mean (walls show as
// thin ellipses along them). Image rows run top to bottom (north up), as in image_io.h. Free
// functions without state: thread-safe. wavog_io (no ROS).
#ifndef WAVOG_MAPPING_IO_NDT_IMAGE_H_
#define WAVOG_MAPPING_IO_NDT_IMAGE_H_

#include "wavog_mapping/core/wavelet_map.h"
#include "wavog_mapping/io/image_io.h"

namespace wavog {

/// Where a picture lies in the map frame: its lower-left corner and its pixel size.
struct PixelFrame {
  double origin_x = 0.0;        ///< map-frame x of the picture's left edge (m)
  double origin_y = 0.0;        ///< map-frame y of the picture's bottom edge (m)
  double metres_per_pixel = 1;  ///< pixel size (m), > 0
};

/// How the Gaussians are drawn.
struct NdtRenderOptions {
  double sigmas = 2.0;             ///< the outline is the ellipse at this Mahalanobis distance
  Rgb occupied_colour{220, 0, 0};  ///< outline of a Gaussian whose cell has P(occ) > 0.5
  Rgb free_colour{255, 150, 0};    ///< outline of one whose cell has P(occ) <= 0.5
  Rgb mean_colour{0, 60, 220};     ///< the dot at the mean
  int max_upscale = 8;             ///< pixels per cell at most (cells of a small map), >= 1
  double max_pixels = 16e6;        ///< the upscaled picture has at most this many pixels
  RenderOptions map;               ///< how the occupancy map under the ellipses is drawn
};

/// Pixels per raster cell for a `width` x `height` raster: the largest k in [1, max_upscale]
/// with width * height * k^2 <= max_pixels (1 when even k = 1 exceeds it).
int ndtUpscale(std::int64_t width, std::int64_t height, const NdtRenderOptions& options);

/// Draws the outline of the ellipse {p : (p - mean)^T cov^-1 (p - mean) = sigmas^2} of one
/// Gaussian (map frame, m and m^2) into `image` placed at `frame`, in `colour`: every pixel the
/// ellipse passes through, clipped to the image. A degenerate covariance (a line, or 0 for one
/// end-point) draws the segment or the single pixel it reduces to; non-finite values draw nothing.
void drawEllipseOutline(Image* image, const PixelFrame& frame, double mean_x, double mean_y,
                        double cov_xx, double cov_xy, double cov_yy, double sigmas, Rgb colour);

/// Colours the pixel holding the map-frame point (x, y) and, when `radius` > 0, the square of
/// (2 radius + 1)^2 pixels around it (clipped to the image).
void drawDot(Image* image, const PixelFrame& frame, double x, double y, int radius, Rgb colour);

/// The NDT picture of one scale: renderRgb(raster) upscaled by ndtUpscale(), then every Gaussian
/// of `layer` (exportNdt at the raster's scale; those outside the raster are clipped) as its
/// outline, coloured by its cell's occupancy, and its mean as a dot (3 x 3 pixels from 6 pixels
/// per cell, else 1). Throws std::invalid_argument when the raster is inconsistent or `layer`
/// has another cell size.
Image renderNdt(const Raster& raster, const NdtLayer& layer,
                const NdtRenderOptions& options = NdtRenderOptions());

}  // namespace wavog

#endif  // WAVOG_MAPPING_IO_NDT_IMAGE_H_
