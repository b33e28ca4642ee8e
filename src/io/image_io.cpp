// PNG / PGM / map_server YAML writers (and small readers for tests and tools). The PNG encoder
// writes one IDAT of zlib-compressed rows, each with the filter type that suits it best; the reader
// accepts all five filter types of the PNG spec, so it also reads files from other encoders that
// use 8-bit grey or RGB without interlacing.
#include "wavog_mapping/io/image_io.h"

#include <zlib.h>

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

namespace wavog {
namespace {

constexpr std::array<std::uint8_t, 8> kPngSignature = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
constexpr int kPngColourGrey = 0;
constexpr int kPngColourRgb = 2;
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

/// Writes `data` to `path` in one go; throws naming the file on failure.
void writeFile(const std::string& path, const std::string& data) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(path + ": cannot open for writing: " + std::strerror(errno));
  out.write(data.data(), static_cast<std::streamsize>(data.size()));
  out.close();
  if (!out) throw std::runtime_error(path + ": write failed: " + std::strerror(errno));
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open: " + std::strerror(errno));
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void putBe32(std::string* out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8)
    out->push_back(static_cast<char>((v >> shift) & 0xffu));
}

std::uint32_t getBe32(const std::string& s, std::size_t pos) {
  std::uint32_t v = 0;
  for (std::size_t i = 0; i < 4; ++i) v = (v << 8) | static_cast<std::uint8_t>(s[pos + i]);
  return v;
}

void putChunk(std::string* out, const char type[4], const std::string& data) {
  putBe32(out, static_cast<std::uint32_t>(data.size()));
  std::string body(type, 4);
  body += data;
  out->append(body);
  const auto crc =
      crc32(0L, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size()));
  putBe32(out, static_cast<std::uint32_t>(crc));
}

/// zlib stream of `raw` at the best compression; throws naming `path` on failure.
std::string deflate(const std::string& path, const std::string& raw) {
  uLongf size = compressBound(static_cast<uLong>(raw.size()));
  std::string packed(size, '\0');
  if (compress2(reinterpret_cast<Bytef*>(&packed[0]), &size,
                reinterpret_cast<const Bytef*>(raw.data()), static_cast<uLong>(raw.size()),
                Z_BEST_COMPRESSION) != Z_OK) {
    throw std::runtime_error(path + ": zlib compression failed");
  }
  packed.resize(size);
  return packed;
}

/// Paeth predictor of the PNG spec (filter type 4).
std::uint8_t paeth(int a, int b, int c) {
  const int p = a + b - c;
  const int pa = std::abs(p - a);
  const int pb = std::abs(p - b);
  const int pc = std::abs(p - c);
  if (pa <= pb && pa <= pc) return static_cast<std::uint8_t>(a);
  if (pb <= pc) return static_cast<std::uint8_t>(b);
  return static_cast<std::uint8_t>(c);
}

/// PNG filter `type` 0..4 (none, sub, up, average, Paeth): the prediction of a byte from its left
/// (a), upper (b) and upper-left (c) neighbours.
int predict(int type, int a, int b, int c) {
  switch (type) {
    case 1:
      return a;
    case 2:
      return b;
    case 3:
      return (a + b) / 2;
    case 4:
      return paeth(a, b, c);
    default:
      return 0;
  }
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
  const double p = 1.0 / (1.0 + std::exp(-static_cast<double>(log_odds)));
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
      if (raster.known[i]) {
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
  const std::size_t stride =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
  // Two encodings, the smaller one kept: no filter, and per row the filter type with the smallest
  // sum of |signed residuals| (the PNG spec's heuristic), which wins on smooth pictures but can
  // lose on graded maps with sharp edges.
  const std::size_t bpp = static_cast<std::size_t>(image.channels);
  std::string plain;
  std::string filtered;
  plain.reserve((stride + 1) * static_cast<std::size_t>(image.height));
  filtered.reserve(plain.capacity());
  std::array<std::vector<std::uint8_t>, 5> candidates;
  for (auto& c : candidates) c.resize(stride);
  for (int y = 0; y < image.height; ++y) {
    const std::uint8_t* row = image.at(0, y);
    const std::uint8_t* up = y > 0 ? image.at(0, y - 1) : nullptr;
    plain.push_back('\0');
    plain.append(reinterpret_cast<const char*>(row), stride);
    std::size_t best = 0;
    long best_cost = -1;
    for (std::size_t f = 0; f < candidates.size(); ++f) {
      long cost = 0;
      for (std::size_t i = 0; i < stride; ++i) {
        const int a = i >= bpp ? row[i - bpp] : 0;
        const int b = up ? up[i] : 0;
        const int c = (up && i >= bpp) ? up[i - bpp] : 0;
        const int predicted = predict(static_cast<int>(f), a, b, c);
        const auto residual = static_cast<std::uint8_t>((row[i] - predicted) & 0xff);
        candidates[f][i] = residual;
        cost += residual < 128 ? residual : 256 - residual;
      }
      if (best_cost < 0 || cost < best_cost) {
        best_cost = cost;
        best = f;
      }
    }
    filtered.push_back(static_cast<char>(best));
    filtered.append(reinterpret_cast<const char*>(candidates[best].data()), stride);
  }
  const std::string a = deflate(path, plain);
  const std::string b = deflate(path, filtered);
  const std::string& packed = a.size() <= b.size() ? a : b;

  std::string ihdr;
  putBe32(&ihdr, static_cast<std::uint32_t>(image.width));
  putBe32(&ihdr, static_cast<std::uint32_t>(image.height));
  ihdr.push_back(8);  // bit depth
  ihdr.push_back(static_cast<char>(image.channels == 1 ? kPngColourGrey : kPngColourRgb));
  ihdr.push_back(0);  // compression: deflate
  ihdr.push_back(0);  // filter method 0
  ihdr.push_back(0);  // no interlace

  std::string out(kPngSignature.begin(), kPngSignature.end());
  putChunk(&out, "IHDR", ihdr);
  putChunk(&out, "IDAT", packed);
  putChunk(&out, "IEND", "");
  writeFile(path, out);
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
  const std::string file = readFile(path);
  auto fail = [&path](const std::string& why) -> std::runtime_error {
    return std::runtime_error(path + ": not a readable PNG: " + why);
  };
  if (file.size() < 8 ||
      !std::equal(kPngSignature.begin(), kPngSignature.end(), file.begin(),
                  [](std::uint8_t a, char b) { return a == static_cast<std::uint8_t>(b); })) {
    throw fail("bad signature");
  }
  Image image;
  std::string idat;
  bool have_header = false;
  bool ended = false;
  std::size_t pos = 8;
  while (!ended) {
    if (pos + 12 > file.size()) throw fail("truncated chunk");
    const std::uint32_t len = getBe32(file, pos);
    if (len > file.size() - pos - 12) throw fail("truncated chunk");
    const std::string type = file.substr(pos + 4, 4);
    const auto crc = crc32(0L, reinterpret_cast<const Bytef*>(file.data() + pos + 4), len + 4);
    if (static_cast<std::uint32_t>(crc) != getBe32(file, pos + 8 + len)) {
      throw fail("CRC mismatch in chunk " + type);
    }
    const std::string data = file.substr(pos + 8, len);
    if (type == "IHDR") {
      if (len != 13) throw fail("bad IHDR");
      image.width = static_cast<int>(getBe32(data, 0));
      image.height = static_cast<int>(getBe32(data, 4));
      const int depth = static_cast<std::uint8_t>(data[8]);
      const int colour = static_cast<std::uint8_t>(data[9]);
      if (depth != 8 || (colour != kPngColourGrey && colour != kPngColourRgb) || data[12] != 0) {
        throw fail("only 8-bit grey or RGB without interlacing is supported");
      }
      image.channels = colour == kPngColourGrey ? 1 : 3;
      if (image.width <= 0 || image.height <= 0 ||
          static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height) >
              kMaxPngPixels) {
        throw fail("bad size");
      }
      have_header = true;
    } else if (type == "IDAT") {
      idat += data;
    } else if (type == "IEND") {
      ended = true;
    }
    pos += 12 + len;
  }
  if (!have_header) throw fail("no IHDR");
  const std::size_t stride =
      static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.channels);
  const std::size_t height = static_cast<std::size_t>(image.height);
  std::string raw((stride + 1) * height, '\0');
  uLongf raw_size = static_cast<uLongf>(raw.size());
  if (uncompress(reinterpret_cast<Bytef*>(&raw[0]), &raw_size,
                 reinterpret_cast<const Bytef*>(idat.data()),
                 static_cast<uLong>(idat.size())) != Z_OK ||
      raw_size != raw.size()) {
    throw fail("damaged image data");
  }
  image.pixels.assign(stride * height, 0);
  const std::size_t bpp = static_cast<std::size_t>(image.channels);
  for (std::size_t y = 0; y < height; ++y) {
    const auto filter = static_cast<std::uint8_t>(raw[y * (stride + 1)]);
    if (filter > 4) throw fail("bad filter type " + std::to_string(filter));
    const auto* in = reinterpret_cast<const std::uint8_t*>(raw.data()) + y * (stride + 1) + 1;
    std::uint8_t* out = image.pixels.data() + y * stride;
    const std::uint8_t* up = y > 0 ? out - stride : nullptr;
    for (std::size_t i = 0; i < stride; ++i) {
      const int a = i >= bpp ? out[i - bpp] : 0;
      const int b = up ? up[i] : 0;
      const int c = (up && i >= bpp) ? up[i - bpp] : 0;
      const int predicted = predict(filter, a, b, c);
      out[i] = static_cast<std::uint8_t>((in[i] + predicted) & 0xff);
    }
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
  const std::string yaml_path = base + ".yaml";
  writeMapServerYaml(yaml_path, yaml);
  return yaml_path;
}

}  // namespace wavog
