// Tests of the NDT pictures (wavog_mapping/io/ndt_image.h): a known covariance draws its 2-sigma
// ellipse through the expected pixels, only pixels the ellipse passes through, as a closed
// outline; degenerate Gaussians draw their segment or their pixel; the upscale rule; renderNdt's
// size, background and mean dots. gtest + wavog_io.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "wavog_mapping/io/image_io.h"
#include "wavog_mapping/io/ndt_image.h"

namespace {

constexpr wavog::Rgb kRed{220, 0, 0};
constexpr int kSize = 41;
constexpr double kPixel = 0.1;  // m

/// A white kSize x kSize RGB picture whose lower-left corner is the map origin, 0.1 m pixels.
wavog::Image whitePicture() {
  wavog::Image image(kSize, kSize, 3);
  for (auto& v : image.pixels) v = 255;
  return image;
}

wavog::PixelFrame frame() {
  wavog::PixelFrame f;
  f.metres_per_pixel = kPixel;
  return f;
}

bool isColour(const wavog::Image& image, int x, int y, wavog::Rgb c) {
  const std::uint8_t* p = image.at(x, y);
  return p[0] == c.r && p[1] == c.g && p[2] == c.b;
}

bool isWhite(const wavog::Image& image, int x, int y) {
  return isColour(image, x, y, wavog::Rgb{255, 255, 255});
}

/// The tests' Gaussian, mean at the centre of pixel (20, 20) of the picture: map (2.05, 2.05).
struct Gaussian {
  double mx = 2.05, my = 2.05;
  double xx = 0.0, xy = 0.0, yy = 0.0;
  /// Mahalanobis distance of a map point (needs a regular covariance).
  double mahalanobis(double x, double y) const {
    const double det = xx * yy - xy * xy;
    const double dx = x - mx;
    const double dy = y - my;
    return std::sqrt((yy * dx * dx - 2.0 * xy * dx * dy + xx * dy * dy) / det);
  }
};

/// A covariance of standard deviations `major` along `angle` (rad) and `minor` across (m).
Gaussian rotated(double major, double minor, double angle) {
  Gaussian g;
  const double c = std::cos(angle);
  const double s = std::sin(angle);
  g.xx = major * major * c * c + minor * minor * s * s;
  g.yy = major * major * s * s + minor * minor * c * c;
  g.xy = (major * major - minor * minor) * c * s;
  return g;
}

/// Map point of the picture position (u, r): u pixels from the left, r from the top.
double mapX(double u) { return u * kPixel; }
double mapY(double r) { return (kSize - r) * kPixel; }

/// Checks that each coloured pixel meets the 2-sigma ellipse (its square holds points on both
/// sides of it) and that each has at least two coloured neighbours (a closed outline, no gaps).
void expectOnlyAClosedOutline(const wavog::Image& image, const Gaussian& g, int* drawn) {
  *drawn = 0;
  for (int r = 0; r < kSize; ++r) {
    for (int u = 0; u < kSize; ++u) {
      if (isWhite(image, u, r)) continue;
      ++*drawn;
      double lo = 1e9;
      double hi = -1e9;
      constexpr int kSub = 8;
      for (int i = 0; i <= kSub; ++i) {
        for (int j = 0; j <= kSub; ++j) {
          const double m = g.mahalanobis(mapX(u + static_cast<double>(i) / kSub),
                                         mapY(r + static_cast<double>(j) / kSub));
          lo = std::min(lo, m);
          hi = std::max(hi, m);
        }
      }
      EXPECT_LE(lo, 2.0) << "pixel (" << u << ", " << r << ") lies outside the ellipse";
      EXPECT_GE(hi, 2.0) << "pixel (" << u << ", " << r << ") lies inside the ellipse";
      int neighbours = 0;
      for (int dr = -1; dr <= 1; ++dr) {
        for (int du = -1; du <= 1; ++du) {
          if ((du != 0 || dr != 0) && !isWhite(image, u + du, r + dr)) ++neighbours;
        }
      }
      EXPECT_GE(neighbours, 2) << "pixel (" << u << ", " << r << ") ends the outline";
    }
  }
}

TEST(NdtEllipse, AxisAlignedCovarianceDrawsItsTwoSigmaOutlineThroughTheAxisTips) {
  // sigma 0.5 m along x, 0.25 m along y: at 2 sigma, semi-axes of 10 and 5 pixels.
  Gaussian g;
  g.xx = 0.25;
  g.yy = 0.0625;
  wavog::Image image = whitePicture();
  wavog::drawEllipseOutline(&image, frame(), g.mx, g.my, g.xx, g.xy, g.yy, 2.0, kRed);
  EXPECT_TRUE(isColour(image, 30, 20, kRed));  // +x tip: map (3.05, 2.05)
  EXPECT_TRUE(isColour(image, 10, 20, kRed));  // -x tip
  EXPECT_TRUE(isColour(image, 20, 15, kRed));  // +y tip (map y up is picture row down)
  EXPECT_TRUE(isColour(image, 20, 25, kRed));  // -y tip
  EXPECT_TRUE(isWhite(image, 20, 20));         // the centre
  EXPECT_TRUE(isWhite(image, 25, 20));         // inside, on the major axis
  EXPECT_TRUE(isWhite(image, 32, 20));         // outside it
  EXPECT_TRUE(isWhite(image, 20, 13));
  int drawn = 0;
  expectOnlyAClosedOutline(image, g, &drawn);
  // Perimeter of the 10 x 5 pixel ellipse (Ramanujan): 48.4 pixels; an 8-connected outline holds
  // between 1/sqrt(2) and 1 pixel per pixel of length, a few more where samples meet at corners.
  const double perimeter = M_PI * (3.0 * 15.0 - std::sqrt(35.0 * 25.0));
  EXPECT_GE(drawn, 0.7 * perimeter);
  EXPECT_LE(drawn, 1.5 * perimeter);
}

TEST(NdtEllipse, RotatedCovarianceDrawsAlongItsMajorAxis) {
  const Gaussian g = rotated(0.5, 0.25, M_PI / 6.0);
  wavog::Image image = whitePicture();
  wavog::drawEllipseOutline(&image, frame(), g.mx, g.my, g.xx, g.xy, g.yy, 2.0, kRed);
  // Major tips at (20.5, 20.5) +- 10 (cos 30, -sin 30) pixels: (29.16, 15.5) and (11.84, 25.5).
  EXPECT_TRUE(isColour(image, 29, 15, kRed));
  EXPECT_TRUE(isColour(image, 11, 25, kRed));
  // The unrotated ellipse's +x tip is outside it, the centre inside.
  EXPECT_TRUE(isWhite(image, 30, 20));
  EXPECT_TRUE(isWhite(image, 20, 20));
  int drawn = 0;
  expectOnlyAClosedOutline(image, g, &drawn);
  EXPECT_GE(drawn, 30);
}

TEST(NdtEllipse, DegenerateCovariancesDrawTheirSegmentOrTheirPixel) {
  wavog::Image line = whitePicture();
  // sigma 0.25 m along x, none across: the segment of +-5 pixels on row 20.
  wavog::drawEllipseOutline(&line, frame(), 2.05, 2.05, 0.0625, 0.0, 0.0, 2.0, kRed);
  for (int r = 0; r < kSize; ++r) {
    for (int u = 0; u < kSize; ++u) {
      EXPECT_EQ(!isWhite(line, u, r), r == 20 && u >= 15 && u <= 25) << u << ", " << r;
    }
  }
  wavog::Image point = whitePicture();
  wavog::drawEllipseOutline(&point, frame(), 2.05, 2.05, 0.0, 0.0, 0.0, 2.0, kRed);
  int drawn = 0;
  for (int r = 0; r < kSize; ++r) {
    for (int u = 0; u < kSize; ++u) drawn += !isWhite(point, u, r);
  }
  EXPECT_EQ(drawn, 1);
  EXPECT_TRUE(isColour(point, 20, 20, kRed));
  // Non-finite values and a Gaussian off the picture draw nothing (and do not crash).
  wavog::Image none = whitePicture();
  wavog::drawEllipseOutline(&none, frame(), NAN, 2.0, 0.01, 0.0, 0.01, 2.0, kRed);
  wavog::drawEllipseOutline(&none, frame(), 2.0, 2.0, INFINITY, 0.0, 0.01, 2.0, kRed);
  wavog::drawEllipseOutline(&none, frame(), -50.0, 2.0, 0.25, 0.0, 0.25, 2.0, kRed);
  for (auto v : none.pixels) ASSERT_EQ(v, 255);
}

TEST(NdtEllipse, DotCoversItsSquareClippedToThePicture) {
  wavog::Image image = whitePicture();
  wavog::drawDot(&image, frame(), 2.05, 2.05, 1, kRed);
  wavog::drawDot(&image, frame(), 0.01, 0.01, 1, kRed);  // lower-left pixel (0, 40)
  int drawn = 0;
  for (int r = 0; r < kSize; ++r) {
    for (int u = 0; u < kSize; ++u) drawn += !isWhite(image, u, r);
  }
  EXPECT_EQ(drawn, 9 + 4);
  EXPECT_TRUE(isColour(image, 21, 21, kRed));
  EXPECT_TRUE(isColour(image, 0, 40, kRed));
  EXPECT_TRUE(isColour(image, 1, 39, kRed));
}

TEST(NdtUpscale, LargestFactorWithinThePixelBudget) {
  const wavog::NdtRenderOptions o;  // at most 8, 16e6 pixels
  EXPECT_EQ(wavog::ndtUpscale(100, 100, o), 8);
  EXPECT_EQ(wavog::ndtUpscale(1000, 1000, o), 4);  // 16e6 exactly
  EXPECT_EQ(wavog::ndtUpscale(1001, 1000, o), 3);
  EXPECT_EQ(wavog::ndtUpscale(2000, 2000, o), 2);
  EXPECT_EQ(wavog::ndtUpscale(10000, 10000, o), 1);
}

TEST(RenderNdt, UpscaledMapWithOutlinesAndMeans) {
  // 4 x 3 cells of 0.5 m at scale 1, origin (1.0, -0.5); all free except the cell (2, 1) of the
  // raster, occupied, holding a Gaussian at its centre (map (2.25, 0.25)).
  wavog::Raster raster;
  raster.scale = 1;
  raster.cell_size = 0.5;
  raster.box = wavog::CellBox{2, -1, 6, 2};
  raster.log_odds.assign(12, -2.0f);
  raster.known.assign(12, 1);
  raster.log_odds[1 * 4 + 2] = 3.0f;
  raster.known[0] = 0;
  wavog::NdtLayer layer;
  layer.scale = 1;
  layer.cell_size = 0.5;
  layer.box = raster.box;
  wavog::NdtCell cell;
  cell.ix = 4;
  cell.iy = 0;
  cell.weight = 7.0;
  cell.mean_x = 2.25;
  cell.mean_y = 0.25;
  cell.cov_xx = 0.01;  // sigma 0.1 m: 2 sigma is 0.2 m = 3.2 pixels of 0.0625 m
  cell.cov_yy = 0.0025;
  cell.log_odds = 3.0f;
  layer.cells.push_back(cell);

  const wavog::NdtRenderOptions options;
  const wavog::Image image = wavog::renderNdt(raster, layer, options);
  ASSERT_EQ(image.channels, 3);
  ASSERT_EQ(image.width, 4 * 8);
  ASSERT_EQ(image.height, 3 * 8);
  wavog::RenderOptions map;
  map.upscale = 8;
  const wavog::Image background = wavog::renderRgb(raster, map);
  // The mean: picture column (2.25 - 1.0) / 0.0625 = 20, row 24 - (0.25 + 0.5) / 0.0625 = 12;
  // a 3 x 3 dot at 8 pixels per cell.
  for (int dr = -1; dr <= 1; ++dr) {
    for (int du = -1; du <= 1; ++du) {
      EXPECT_TRUE(isColour(image, 20 + du, 12 + dr, options.mean_colour)) << du << ", " << dr;
    }
  }
  // The +x tip of the outline at column 20 + 3.2, row 12: pixel (23, 12), in the occupied colour.
  EXPECT_TRUE(isColour(image, 23, 12, options.occupied_colour));
  // Away from the Gaussian the picture is the occupancy map's, unknown cell included.
  for (int r = 0; r < image.height; ++r) {
    for (int u = 0; u < image.width; ++u) {
      if (std::abs(u - 20) <= 4 && std::abs(r - 12) <= 4) continue;
      const std::uint8_t* a = image.at(u, r);
      const std::uint8_t* b = background.at(u, r);
      ASSERT_TRUE(a[0] == b[0] && a[1] == b[1] && a[2] == b[2]) << u << ", " << r;
    }
  }
  // A free cell's Gaussian takes the free colour.
  layer.cells[0].log_odds = -1.0f;
  EXPECT_TRUE(isColour(wavog::renderNdt(raster, layer, options), 23, 12, options.free_colour));
  // Gaussians of another scale are refused.
  layer.cell_size = 0.25;
  EXPECT_THROW(wavog::renderNdt(raster, layer, options), std::invalid_argument);
}

}  // namespace
