// Tests of the image writers: raster rendering (orientation, grey levels, unknown colour), PNG and
// PGM round trips, the map_server YAML, and the errors. The PNGs writePng makes are decoded by an
// independent decoder, Python's PIL (its own PNG reader, not libpng), so that a mistake made the
// same way in our writer and reader cannot pass. gtest + wavog_io (+ python3-pil at run time).
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "wavog_mapping/io/image_io.h"

namespace {

namespace fs = std::filesystem;

class ImageIo : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("wavog_image_io_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) + "_" +
            std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }

  /// 3 x 2 raster at scale 1, 0.1 m cells, origin (-0.2, 0.4): row y=0 is (free, occ, unknown),
  /// row y=1 is (prior-ish known, unknown, free).
  static wavog::Raster sample() {
    wavog::Raster r;
    r.scale = 1;
    r.cell_size = 0.1;
    r.box = wavog::CellBox{-2, 4, 1, 6};
    r.log_odds = {-20.0f, 20.0f, 0.0f, 0.0f, 0.0f, -20.0f};
    r.known = {1, 1, 0, 1, 0, 1};
    return r;
  }

  fs::path dir_;
};

std::string readText(const std::string& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

/// A PNG decoded by PIL: its mode ("L", "RGB", ...), size and raw pixel bytes (row-major, top
/// row first). Fails the test when python3 or PIL cannot decode the file.
struct PilImage {
  std::string mode;
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> pixels;
};

PilImage decodeWithPil(const std::string& png) {
  const std::string raw = png + ".pil";
  const std::string cmd = std::string(WAVOG_PYTHON) +
                          " -c 'import sys; from PIL import Image; im = Image.open(sys.argv[1]); "
                          "im.load(); open(sys.argv[2], \"wb\").write(im.tobytes()); "
                          "print(im.mode, im.size[0], im.size[1])' " +
                          png + " " + raw;
  PilImage out;
  std::FILE* pipe = ::popen(cmd.c_str(), "r");
  if (pipe == nullptr) {
    ADD_FAILURE() << "cannot run " << cmd;
    return out;
  }
  char mode[16] = {0};
  const int fields = std::fscanf(pipe, "%15s %d %d", mode, &out.width, &out.height);
  const int status = ::pclose(pipe);
  EXPECT_EQ(fields, 3) << cmd;
  EXPECT_EQ(status, 0) << cmd;
  out.mode = mode;
  const std::string bytes = readText(raw);
  out.pixels.assign(bytes.begin(), bytes.end());
  return out;
}

TEST(GreyFromLogOdds, FreeIsWhiteOccupiedIsBlackLinearInProbability) {
  EXPECT_EQ(wavog::greyFromLogOdds(-30.0f), 254);
  EXPECT_EQ(wavog::greyFromLogOdds(30.0f), 0);
  EXPECT_EQ(wavog::greyFromLogOdds(0.0f), 127);
  EXPECT_NEAR(wavog::greyFromLogOdds(std::log(3.0f)), 63.5, 0.6);  // P = 0.75
}

TEST_F(ImageIo, RenderGreyPutsHighestYOnTopAndReservesTheUnknownGrey) {
  wavog::Raster r = sample();
  // A known cell whose grey level would be 205 must not look unknown.
  r.log_odds[3] = static_cast<float>(std::log((254.0 - 205.0) / 205.0));
  ASSERT_EQ(wavog::greyFromLogOdds(r.log_odds[3]), 205);
  const wavog::Image g = wavog::renderGrey(r);
  ASSERT_EQ(g.width, 3);
  ASSERT_EQ(g.height, 2);
  ASSERT_EQ(g.channels, 1);
  EXPECT_EQ(g.pixels, (std::vector<std::uint8_t>{204, 205, 254, 254, 0, 205}));

  wavog::RenderOptions big;
  big.upscale = 2;
  const wavog::Image g2 = wavog::renderGrey(r, big);
  ASSERT_EQ(g2.width, 6);
  ASSERT_EQ(g2.height, 4);
  EXPECT_EQ(*g2.at(5, 3), 205);
  EXPECT_EQ(*g2.at(3, 3), 0);
  EXPECT_EQ(*g2.at(2, 2), 0);
  EXPECT_EQ(*g2.at(1, 1), 204);
}

TEST_F(ImageIo, RenderRgbShowsUnknownInColour) {
  const wavog::Image c = wavog::renderRgb(sample());
  ASSERT_EQ(c.channels, 3);
  const std::uint8_t* unknown = c.at(2, 1);  // raster (2, 0)
  EXPECT_EQ(unknown[0], 170);
  EXPECT_EQ(unknown[1], 200);
  EXPECT_EQ(unknown[2], 235);
  const std::uint8_t* occ = c.at(1, 1);
  EXPECT_EQ(occ[0], 0);
  EXPECT_EQ(occ[1], 0);
  EXPECT_EQ(occ[2], 0);
  EXPECT_EQ(c.at(0, 0)[0], 127);
}

/// A grey and an RGB image whose pixels change from byte to byte (every PNG filter type pays).
std::vector<wavog::Image> testImages() {
  std::vector<wavog::Image> images = {wavog::Image(37, 11, 1), wavog::Image(5, 300, 3)};
  for (std::size_t i = 0; i < images[0].pixels.size(); ++i)
    images[0].pixels[i] = static_cast<std::uint8_t>(i * 7);
  for (std::size_t i = 0; i < images[1].pixels.size(); ++i)
    images[1].pixels[i] = static_cast<std::uint8_t>(i * 13 + 1);
  return images;
}

TEST_F(ImageIo, PngWrittenIsDecodedExactlyByAnIndependentDecoderAndReadBack) {
  for (const wavog::Image& image : testImages()) {
    wavog::writePng(path("i.png"), image);
    const PilImage pil = decodeWithPil(path("i.png"));
    EXPECT_EQ(pil.mode, image.channels == 1 ? "L" : "RGB");
    EXPECT_EQ(pil.width, image.width);
    EXPECT_EQ(pil.height, image.height);
    EXPECT_EQ(pil.pixels, image.pixels);
    const wavog::Image back = wavog::readPng(path("i.png"));
    EXPECT_EQ(back.width, image.width);
    EXPECT_EQ(back.height, image.height);
    EXPECT_EQ(back.channels, image.channels);
    EXPECT_EQ(back.pixels, image.pixels);
  }
  // A rendered map: the top row is the raster's highest y (see RenderRgbShowsUnknownInColour).
  const wavog::Image map = wavog::renderRgb(sample());
  wavog::writePng(path("map.png"), map);
  EXPECT_EQ(decodeWithPil(path("map.png")).pixels, map.pixels);
  EXPECT_EQ(readText(path("map.png")).substr(1, 3), "PNG");
}

TEST_F(ImageIo, PngOfAnIndependentEncoderIsRead) {
  for (const wavog::Image& image : testImages()) {
    const std::string raw = path("pil.raw");
    std::ofstream(raw, std::ios::binary)
        .write(reinterpret_cast<const char*>(image.pixels.data()),
               static_cast<std::streamsize>(image.pixels.size()));
    const std::string cmd = std::string(WAVOG_PYTHON) +
                            " -c 'import sys; from PIL import Image; "
                            "Image.frombytes(sys.argv[1], (int(sys.argv[2]), int(sys.argv[3])), "
                            "open(sys.argv[4], \"rb\").read()).save(sys.argv[5])' " +
                            (image.channels == 1 ? "L " : "RGB ") + std::to_string(image.width) +
                            " " + std::to_string(image.height) + " " + raw + " " + path("pil.png");
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
    const wavog::Image read = wavog::readPng(path("pil.png"));
    EXPECT_EQ(read.channels, image.channels);
    EXPECT_EQ(read.pixels, image.pixels);
  }
}

TEST_F(ImageIo, PgmAndMapServerYaml) {
  const wavog::Raster r = sample();
  const std::string yaml = wavog::writeMapServerMap(path("map_s1"), r);
  EXPECT_EQ(yaml, path("map_s1.yaml"));
  const wavog::Image pgm = wavog::readPgm(path("map_s1.pgm"));
  EXPECT_EQ(pgm.pixels, wavog::renderGrey(r).pixels);
  EXPECT_EQ(readText(yaml),
            "image: map_s1.pgm\nresolution: 0.10000000000000001\n"
            "origin: [-0.20000000000000001, 0.40000000000000002, 0]\nnegate: 0\n"
            "occupied_thresh: 0.65000000000000002\nfree_thresh: 0.19600000000000001\n");
  // map_server's trinary reading of the PGM gives back the known / unknown split.
  for (int y = 0; y < pgm.height; ++y) {
    for (int x = 0; x < pgm.width; ++x) {
      const double p = (255.0 - *pgm.at(x, y)) / 255.0;
      const bool unknown = !(p > 0.65) && !(p < 0.196);
      const std::size_t i = static_cast<std::size_t>((pgm.height - 1 - y) * pgm.width + x);
      EXPECT_EQ(unknown, r.known[i] == 0 || r.log_odds[i] == 0.0f) << x << "," << y;
    }
  }
}

TEST_F(ImageIo, NeverWritesThroughASymlinkPlantedAtTheNames) {
  // Files outside the target directory, and symlinks to them at each name the writers use.
  const fs::path outside = dir_ / "outside";
  fs::create_directories(outside);
  const std::string kept = "not to be overwritten\n";
  for (const std::string name : {"map_s1.pgm", "map_s1.yaml", "map_s1.png"}) {
    std::ofstream(outside / name) << kept;
    fs::create_symlink(outside / name, dir_ / name);
  }
  const wavog::Raster r = sample();
  wavog::writeMapServerMap(path("map_s1"), r);
  wavog::writePng(path("map_s1.png"), wavog::renderRgb(r));
  for (const std::string name : {"map_s1.pgm", "map_s1.yaml", "map_s1.png"}) {
    SCOPED_TRACE(name);
    EXPECT_EQ(readText((outside / name).string()), kept);
    EXPECT_FALSE(fs::is_symlink(dir_ / name));  // the link itself was replaced by the new file
    EXPECT_TRUE(fs::is_regular_file(dir_ / name));
  }
  EXPECT_EQ(wavog::readPgm(path("map_s1.pgm")).pixels, wavog::renderGrey(r).pixels);
  EXPECT_EQ(wavog::readPng(path("map_s1.png")).pixels, wavog::renderRgb(r).pixels);
  // No temporary is left beside them.
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(dir_)) files += e.is_directory() ? 0 : 1;
  EXPECT_EQ(files, 3u);
}

TEST_F(ImageIo, ErrorsNameTheFile) {
  const wavog::Image img(2, 2, 1);
  const std::string bad = path("no/such/dir/x.png");
  try {
    wavog::writePng(bad, img);
    FAIL() << "no exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
  }
  wavog::Image wrong(2, 2, 1);
  wrong.pixels.pop_back();
  EXPECT_THROW(wavog::writePng(path("w.png"), wrong), std::runtime_error);
  EXPECT_THROW(wavog::writePgm(path("w.pgm"), wavog::Image(2, 2, 3)), std::runtime_error);
  wavog::writePgm(path("ok.pgm"), img);
  EXPECT_THROW(wavog::readPng(path("ok.pgm")), std::runtime_error);
  EXPECT_THROW(wavog::readPgm(path("missing.pgm")), std::runtime_error);
  wavog::writePng(path("ok.png"), img);
  std::string bytes = readText(path("ok.png"));
  const std::size_t idat = bytes.find("IDAT");  // a damaged byte in the image data
  ASSERT_NE(idat, std::string::npos);
  bytes[idat + 6] = static_cast<char>(bytes[idat + 6] ^ 1);
  std::ofstream(path("flip.png"), std::ios::binary) << bytes;
  EXPECT_THROW(wavog::readPng(path("flip.png")), std::runtime_error);
}

}  // namespace
