// NDT pictures (ndt_image.h): the occupancy picture of image_io.cpp, upscaled, with each Gaussian's
// ellipse outline sampled along its parametric form and a dot at its mean.
#include "wavog_mapping/io/ndt_image.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace wavog {
namespace {

// Samples along an outline are at most this far apart (pixels), so that consecutive samples fall
// in the same or touching pixels and the outline has no gaps.
constexpr double kMaxSampleStepPx = 0.5;
// An outline never takes more samples than this (a huge covariance against a tiny pixel).
constexpr double kMaxSamples = 1 << 20;
// Pixels per cell from which the mean is drawn as a 3 x 3 dot rather than a single pixel.
constexpr int kBigDotUpscale = 6;

void setPixel(Image* image, double u, double r, Rgb colour) {
  if (!(u >= 0.0 && r >= 0.0 && u < image->width && r < image->height)) return;
  std::uint8_t* px = image->at(static_cast<int>(u), static_cast<int>(r));
  px[0] = colour.r;
  px[1] = colour.g;
  px[2] = colour.b;
}

// Picture coordinates (u to the right, r down, both in pixels) of a map-frame point.
double columnOf(const PixelFrame& f, double x) { return (x - f.origin_x) / f.metres_per_pixel; }
double rowOf(const Image& image, const PixelFrame& f, double y) {
  return image.height - (y - f.origin_y) / f.metres_per_pixel;
}

void checkRgb(const Image& image) {
  if (image.channels != 3) throw std::invalid_argument("NDT drawing needs an RGB image");
}

}  // namespace

int ndtUpscale(std::int64_t width, std::int64_t height, const NdtRenderOptions& options) {
  const double cells = static_cast<double>(std::max<std::int64_t>(1, width)) *
                       static_cast<double>(std::max<std::int64_t>(1, height));
  int k = std::max(1, options.max_upscale);
  while (k > 1 && cells * k * k > options.max_pixels) --k;
  return k;
}

void drawEllipseOutline(Image* image, const PixelFrame& frame, double mean_x, double mean_y,
                        double cov_xx, double cov_xy, double cov_yy, double sigmas, Rgb colour) {
  checkRgb(*image);
  if (!std::isfinite(mean_x) || !std::isfinite(mean_y) || !std::isfinite(cov_xx) ||
      !std::isfinite(cov_xy) || !std::isfinite(cov_yy) || !std::isfinite(sigmas) ||
      !(frame.metres_per_pixel > 0.0)) {
    return;
  }
  // Semi-axes in pixels, and the major axis as a unit vector in the map frame (a degenerate
  // covariance gives a line or a point).
  const NdtAxes axes = principalAxes(cov_xx, cov_xy, cov_yy);
  const double a = std::fabs(sigmas) * axes.sigma_major / frame.metres_per_pixel;
  const double b = std::fabs(sigmas) * axes.sigma_minor / frame.metres_per_pixel;
  const double ex = std::cos(axes.yaw);
  const double ey = std::sin(axes.yaw);
  const double u0 = columnOf(frame, mean_x);
  const double r0 = rowOf(*image, frame, mean_y);
  // Arc length between samples <= a * dt (a >= b); the map's y is the picture's -r.
  const double samples =
      std::min(kMaxSamples, std::max(8.0, std::ceil(2.0 * M_PI * a / kMaxSampleStepPx)));
  const auto n = static_cast<int>(samples);
  for (int i = 0; i < n; ++i) {
    const double t = 2.0 * M_PI * i / n;
    const double along = a * std::cos(t);
    const double across = b * std::sin(t);
    setPixel(image, u0 + along * ex - across * ey, r0 - (along * ey + across * ex), colour);
  }
}

void drawDot(Image* image, const PixelFrame& frame, double x, double y, int radius, Rgb colour) {
  checkRgb(*image);
  if (!std::isfinite(x) || !std::isfinite(y) || !(frame.metres_per_pixel > 0.0)) return;
  const double u = std::floor(columnOf(frame, x));
  const double r = std::floor(rowOf(*image, frame, y));
  for (int dr = -radius; dr <= radius; ++dr) {
    for (int du = -radius; du <= radius; ++du) setPixel(image, u + du, r + dr, colour);
  }
}

Image renderNdt(const Raster& raster, const NdtLayer& layer, const NdtRenderOptions& options) {
  if (!layer.cells.empty() &&
      !(std::fabs(layer.cell_size - raster.cell_size) <= 1e-9 * raster.cell_size)) {
    throw std::invalid_argument("renderNdt: Gaussians of cell size " +
                                std::to_string(layer.cell_size) + " m over a raster of " +
                                std::to_string(raster.cell_size) + " m");
  }
  RenderOptions map = options.map;
  map.upscale = ndtUpscale(raster.box.width(), raster.box.height(), options);
  Image image = renderRgb(raster, map);  // checks the raster
  PixelFrame frame;
  frame.origin_x = raster.originX();
  frame.origin_y = raster.originY();
  frame.metres_per_pixel = raster.cell_size / map.upscale;
  for (const NdtCell& c : layer.cells) {
    drawEllipseOutline(&image, frame, c.mean_x, c.mean_y, c.cov_xx, c.cov_xy, c.cov_yy,
                       options.sigmas,
                       c.log_odds > 0.0f ? options.occupied_colour : options.free_colour);
  }
  // Dots after every outline, so that a neighbour's outline never hides a mean.
  const int radius = map.upscale >= kBigDotUpscale ? 1 : 0;
  for (const NdtCell& c : layer.cells) {
    drawDot(&image, frame, c.mean_x, c.mean_y, radius, options.mean_colour);
  }
  return image;
}

}  // namespace wavog
