// PNG / PGM / map_server YAML writers (and small readers for tests and tools). PNG goes through
// libpng's simplified API (8-bit grey or RGB); PGM and the YAML are written here. Every file is
// written whole through wavog::writeFileAtomically: never through a symlink planted at its name,
// never half-written.
#include "wavog_mapping/io/image_io.h"

#include <png.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iomanip>
#include <iterator>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "wavog_mapping/core/atomic_file.h"

namespace wavog {
namespace {

constexpr std::size_t kMaxPngPixels = std::size_t{1} << 30;  // refuse absurd sizes when reading

void checkImage(const std::string& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 || (image.channels != 1 && image.channels != 3) ||
      image.pixels.size() != static_cast<std::size_t>(image.width) *
                                 static_cast<std::size_t>(image.height) *
                                 static_cast<std::size_t>(image.channels)) {
    throw std::runtime_error(path + ": cannot write an image of " + std::to_string(image.width) +
                             " x " + std::to_string(image.height) + " x " +
                             std::to_string(image.channels) + " with " +
                             std::to_string(image.pixels.size()) + " bytes");
  }
}

/// Writes `data` to `path` (wavog::writeFileAtomically); throws naming the file on failure.
void writeFile(const std::string& path, const std::string& data) {
  writeFileAtomically(path, data.data(), data.size());
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// Image row of raster row `ry` (rows are flipped so that +y is up in the picture).
int imageRow(const Raster& raster, std::int64_t ry) {
  return static_cast<int>(raster.box.height() - 1 - ry);
}

std::string formatDouble(double v) {
  std::ostringstream s;
  s << std::setprecision(17) << v;
  return s.str();
}

}  // namespace

std::uint8_t greyFromLogOdds(float log_odds) {
  if (std::isnan(log_odds)) return 127;
  const double p = probabilityFromLogOdds(log_odds);
  return static_cast<std::uint8_t>(std::lround(254.0 * (1.0 - p)));
}

Image renderRgb(const Raster& raster, const RenderOptions& options) {
  const Image grey = renderGrey(raster, options);
  Image rgb(grey.width, grey.height, 3);
  const int k = std::max(1, options.upscale);
  for (int y = 0; y < grey.height; ++y) {
    for (int x = 0; x < grey.width; ++x) {
      const std::int64_t rx = x / k;
      const std::int64_t ry = raster.box.height() - 1 - y / k;
      const std::size_t i = static_cast<std::size_t>(ry * raster.box.width() + rx);
      std::uint8_t* px = rgb.at(x, y);
      if (raster.known[i]) {
        px[0] = px[1] = px[2] = *grey.at(x, y);
      } else {
        px[0] = options.unknown_colour.r;
        px[1] = options.unknown_colour.g;
        px[2] = options.unknown_colour.b;
      }
    }
  }
  return rgb;
}

Image renderGrey(const Raster& raster, const RenderOptions& options) {
  const std::int64_t w = raster.box.width();
  const std::int64_t h = raster.box.height();
  const int k = std::max(1, options.upscale);
  if (w <= 0 || h <= 0 || raster.log_odds.size() != static_cast<std::size_t>(w * h) ||
      raster.known.size() != raster.log_odds.size()) {
    throw std::invalid_argument("renderGrey: raster of " + std::to_string(w) + " x " +
                                std::to_string(h) + " cells holds " +
                                std::to_string(raster.log_odds.size()) + " values");
  }
  Image image(static_cast<int>(w) * k, static_cast<int>(h) * k, 1);
  for (std::int64_t ry = 0; ry < h; ++ry) {
    const int row = imageRow(raster, ry) * k;
    for (std::int64_t rx = 0; rx < w; ++rx) {
      const std::size_t i = static_cast<std::size_t>(ry * w + rx);
      std::uint8_t v = options.unknown_grey;
      if (options.values.trinary) {
        const std::int8_t g = gridValue(raster.log_odds[i], raster.known[i] != 0, options.values);
        if (g == 100) v = 0;
        if (g == 0) v = 254;
      } else if (raster.known[i]) {
        v = greyFromLogOdds(raster.log_odds[i]);
        if (v == options.unknown_grey) v = static_cast<std::uint8_t>(v > 0 ? v - 1 : 1);
      }
      for (int dy = 0; dy < k; ++dy) {
        std::uint8_t* px = image.at(static_cast<int>(rx) * k, row + dy);
        std::fill(px, px + k, v);
      }
    }
  }
  return image;
}

void writePng(const std::string& path, const Image& image) {
  checkImage(path, image);
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  png.width = static_cast<png_uint_32>(image.width);
  png.height = static_cast<png_uint_32>(image.height);
  png.format = image.channels == 1 ? PNG_FORMAT_GRAY : PNG_FORMAT_RGB;
  // Encoded in memory (first the size, then the bytes), then written as every other file.
  png_alloc_size_t size = 0;
  std::vector<unsigned char> encoded;
  if (png_image_write_to_memory(&png, nullptr, &size, 0, image.pixels.data(), 0, nullptr)) {
    encoded.resize(size);
    if (!png_image_write_to_memory(&png, encoded.data(), &size, 0, image.pixels.data(), 0,
                                   nullptr)) {
      size = 0;
    }
  }
  if (size == 0) {
    const std::string why = png.message;
    png_image_free(&png);
    throw std::runtime_error(path + ": cannot write the PNG: " + why);
  }
  writeFileAtomically(path, encoded.data(), size);
}

void writePgm(const std::string& path, const Image& image) {
  checkImage(path, image);
  if (image.channels != 1) throw std::runtime_error(path + ": a PGM needs a grey image");
  std::string out =
      "P5\n" + std::to_string(image.width) + " " + std::to_string(image.height) + "\n255\n";
  out.append(reinterpret_cast<const char*>(image.pixels.data()), image.pixels.size());
  writeFile(path, out);
}

Image readPng(const std::string& path) {
  png_image png{};
  png.version = PNG_IMAGE_VERSION;
  auto fail = [&](const std::string& why) {
    png_image_free(&png);
    return std::runtime_error(path + ": not a readable PNG: " + why);
  };
  if (!png_image_begin_read_from_file(&png, path.c_str())) throw fail(png.message);
  if (png.width == 0 || png.height == 0 ||
      static_cast<std::size_t>(png.width) * png.height > kMaxPngPixels) {
    throw fail("bad size");
  }
  const bool colour = (png.format & PNG_FORMAT_FLAG_COLOR) != 0;
  png.format = colour ? PNG_FORMAT_RGB : PNG_FORMAT_GRAY;
  Image image(static_cast<int>(png.width), static_cast<int>(png.height), colour ? 3 : 1);
  if (!png_image_finish_read(&png, nullptr, image.pixels.data(), 0, nullptr)) {
    throw fail(png.message);
  }
  return image;
}

Image readPgm(const std::string& path) {
  const std::string file = readFile(path);
  std::size_t pos = 0;
  // Header fields are separated by whitespace; '#' starts a comment up to the end of the line.
  auto field = [&]() -> long {
    while (pos < file.size()) {
      if (file[pos] == '#') {
        while (pos < file.size() && file[pos] != '\n') ++pos;
      } else if (std::isspace(static_cast<unsigned char>(file[pos]))) {
        ++pos;
      } else {
        break;
      }
    }
    std::size_t end = pos;
    while (end < file.size() && std::isdigit(static_cast<unsigned char>(file[end]))) ++end;
    if (end == pos) throw std::runtime_error(path + ": not a binary PGM: bad header");
    const long v = std::strtol(file.substr(pos, end - pos).c_str(), nullptr, 10);
    pos = end;
    return v;
  };
  if (file.compare(0, 2, "P5") != 0) throw std::runtime_error(path + ": not a binary PGM (P5)");
  pos = 2;
  const long w = field();
  const long h = field();
  const long maxval = field();
  if (w <= 0 || h <= 0 || maxval <= 0 || maxval > 255 || w * h > static_cast<long>(kMaxPngPixels)) {
    throw std::runtime_error(path + ": unsupported PGM (size or maxval)");
  }
  ++pos;  // the single whitespace after maxval
  Image image(static_cast<int>(w), static_cast<int>(h), 1);
  if (file.size() < pos + image.pixels.size()) throw std::runtime_error(path + ": truncated PGM");
  std::memcpy(image.pixels.data(), file.data() + pos, image.pixels.size());
  return image;
}

void writeMapServerYaml(const std::string& path, const MapServerYaml& yaml) {
  std::ostringstream s;
  s << "image: " << yaml.image << "\n"
    << "resolution: " << formatDouble(yaml.resolution) << "\n"
    << "origin: [" << formatDouble(yaml.origin_x) << ", " << formatDouble(yaml.origin_y) << ", "
    << formatDouble(yaml.origin_yaw) << "]\n"
    << "negate: " << yaml.negate << "\n"
    << "occupied_thresh: " << formatDouble(yaml.occupied_thresh) << "\n"
    << "free_thresh: " << formatDouble(yaml.free_thresh) << "\n";
  writeFile(path, s.str());
}

std::string writeMapServerMap(const std::string& base, const Raster& raster,
                              const RenderOptions& options) {
  RenderOptions one_to_one = options;
  one_to_one.upscale = 1;  // map_server needs one pixel per cell
  writePgm(base + ".pgm", renderGrey(raster, one_to_one));
  MapServerYaml yaml;
  const std::size_t slash = base.find_last_of('/');
  yaml.image = (slash == std::string::npos ? base : base.substr(slash + 1)) + ".pgm";
  yaml.resolution = raster.cell_size;
  yaml.origin_x = raster.originX();
  yaml.origin_y = raster.originY();
  yaml.occupied_thresh = options.values.occupied_thresh;
  yaml.free_thresh = options.values.free_thresh;
  const std::string yaml_path = base + ".yaml";
  writeMapServerYaml(yaml_path, yaml);
  return yaml_path;
}

}  // namespace wavog
