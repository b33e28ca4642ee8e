// Map pictures: 8-bit grey or RGB images written as PNG (libpng) or PGM, rendering of a
// wavog::Raster (known cells in grey levels from P(occ), unknown in a distinct colour), and the
// map_server pair (PGM + YAML). Image rows run top to bottom (north up): row 0 holds the raster's
// highest y. Free functions without state: thread-safe. Lives in wavog_io (std, zlib, libpng; no
// ROS).
#ifndef WAVOG_MAPPING_IO_IMAGE_IO_H_
#define WAVOG_MAPPING_IO_IMAGE_IO_H_

#include <cstdint>
#include <string>
#include <vector>

#include "wavog_mapping/core/wavelet_map.h"

namespace wavog {

/// An 8-bit image, row-major, top row first; `channels` is 1 (grey) or 3 (RGB).
struct Image {
  int width = 0;
  int height = 0;
  int channels = 1;
  std::vector<std::uint8_t> pixels;  ///< width * height * channels bytes

  Image() = default;
  Image(int w, int h, int c)
      : width(w),
        height(h),
        channels(c),
        pixels(static_cast<std::size_t>(w) * static_cast<std::size_t>(h) *
               static_cast<std::size_t>(c)) {}
  std::uint8_t* at(int x, int y) {
    return &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                    static_cast<std::size_t>(x)) *
                   static_cast<std::size_t>(channels)];
  }
  const std::uint8_t* at(int x, int y) const {
    return &pixels[(static_cast<std::size_t>(y) * static_cast<std::size_t>(width) +
                    static_cast<std::size_t>(x)) *
                   static_cast<std::size_t>(channels)];
  }
};

/// An RGB colour.
struct Rgb {
  std::uint8_t r = 0;
  std::uint8_t g = 0;
  std::uint8_t b = 0;
};

/// How a raster becomes a picture.
struct RenderOptions {
  /// Colour of never-observed cells in colour renderings (PNG); a pale blue, never a grey.
  Rgb unknown_colour{170, 200, 235};
  /// Grey level of never-observed cells in grey renderings: 205 is what map_server reads as
  /// unknown with its default thresholds. Known cells never take this level (moved to 204).
  std::uint8_t unknown_grey = 205;
  /// Pixels per raster cell (>= 1), for small maps that should be seen.
  int upscale = 1;
  /// Grey renderings and map_server images: graded (greyFromLogOdds, the default), or with
  /// values.trinary the published values: occupied 0, free 254, between unknown_grey. A map_server
  /// YAML states values.occupied_thresh and values.free_thresh.
  GridValues values{false, 0.65, 0.196};
};

/// Grey level of a known cell: 254 (free, P = 0) down to 0 (occupied, P = 1), linear in P(occ).
std::uint8_t greyFromLogOdds(float log_odds);

/// RGB picture of a raster: known cells grey (greyFromLogOdds), unknown in unknown_colour.
Image renderRgb(const Raster& raster, const RenderOptions& options = RenderOptions());
/// Grey picture of a raster: known cells greyFromLogOdds, unknown unknown_grey.
Image renderGrey(const Raster& raster, const RenderOptions& options = RenderOptions());

/// Writes a PNG (8-bit grey or RGB) with libpng. Throws std::runtime_error naming the file
/// when it cannot be written or the image is inconsistent (size, channels).
void writePng(const std::string& path, const Image& image);
/// Writes a binary PGM (P5, maxval 255) of a grey image. Throws std::runtime_error.
void writePgm(const std::string& path, const Image& image);

/// Reads a PNG with libpng as 8-bit grey (grey files) or RGB (colour files; alpha dropped).
/// Throws std::runtime_error naming the file for anything else or a damaged file.
Image readPng(const std::string& path);
/// Reads a binary PGM (P5, maxval <= 255). Throws std::runtime_error naming the file.
Image readPgm(const std::string& path);

/// The fields of a map_server map YAML.
struct MapServerYaml {
  std::string image;         ///< image file, relative to the YAML's folder
  double resolution = 0.05;  ///< metres per pixel
  double origin_x = 0.0;     ///< map-frame position of the lower-left pixel's corner (m)
  double origin_y = 0.0;
  double origin_yaw = 0.0;        ///< rad
  int negate = 0;                 ///< 0: white is free, black occupied
  double occupied_thresh = 0.65;  ///< pixels with (255 - v) / 255 above are occupied
  double free_thresh = 0.196;     ///< pixels with (255 - v) / 255 below are free
};

/// Writes a map_server YAML. Throws std::runtime_error naming the file.
void writeMapServerYaml(const std::string& path, const MapServerYaml& yaml);

/// Writes `<base>.pgm` (renderGrey) and `<base>.yaml` (image name, resolution = raster cell size,
/// origin = raster origin, options.values' thresholds) so that `map_server <base>.yaml` serves the
/// raster, unknown as -1: with options.values.trinary, the very values the mapper publishes.
/// Returns the YAML path. Throws std::runtime_error.
std::string writeMapServerMap(const std::string& base, const Raster& raster,
                              const RenderOptions& options = RenderOptions());

}  // namespace wavog

#endif  // WAVOG_MAPPING_IO_IMAGE_IO_H_
