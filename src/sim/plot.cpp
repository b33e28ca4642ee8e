#include "plot.h"

#include <cctype>
#include <cstdlib>
#include <map>

namespace wavog {
namespace sim {
namespace {

// 3x5 glyphs, rows top to bottom, '#' lit. Designed for this file.
const std::map<char, const char*>& glyphs() {
  static const std::map<char, const char*> kGlyphs = {
      {'0', "####.##.##.####"}, {'1', ".#.##..#..#.###"}, {'2', "###..#####..###"},
      {'3', "###..####..####"}, {'4', "#.##.####..#..#"}, {'5', "####..###..####"},
      {'6', "####..####.####"}, {'7', "###..#..#..#..#"}, {'8', "####.#####.####"},
      {'9', "####.####..####"}, {'a', "####.#####.##.#"}, {'b', "##.#.###.#.###."},
      {'c', "####..#..#..###"}, {'d', "##.#.##.##.###."}, {'e', "####..####..###"},
      {'f', "####..####..#.."}, {'g', "####..#.##.####"}, {'h', "#.##.#####.##.#"},
      {'i', "###.#..#..#.###"}, {'j', "..#..#..##.####"}, {'k', "#.##.###.#.##.#"},
      {'l', "#..#..#..#..###"}, {'m', "#.########.##.#"}, {'n', "##.#.##.##.##.#"},
      {'o', "####.##.##.####"}, {'p', "####.#####..#.."}, {'q', "####.##.####..#"},
      {'r', "##.#.###.#.##.#"}, {'s', "####..###..####"}, {'t', "###.#..#..#..#."},
      {'u', "#.##.##.##.####"}, {'v', "#.##.##.##.#.#."}, {'w', "#.##.########.#"},
      {'x', "#.##.#.#.#.##.#"}, {'y', "#.##.#.#..#..#."}, {'z', "###..#.#.#..###"},
      {' ', "..............."}, {'/', "..#..#.#.#..#.."}, {'_', "............###"},
      {'.', ".............#."}, {'-', "......###......"}, {'(', ".#.#..#..#...#."},
      {')', ".#...#..#..#.#."}, {':', "....#.....#...."}, {'%', "#.#..#.#.#..#.#"},
      {'=', "...###...###..."}, {'+', "....#.###.#...."}, {',', "..........#.#.."},
      {'<', "..#.#.#...#...#"}, {'>', "#...#...#.#.#.."}, {'|', ".#..#..#..#..#."},
  };
  return kGlyphs;
}

}  // namespace

void putPixel(Image* image, int x, int y, Rgb colour) {
  if (x < 0 || y < 0 || x >= image->width || y >= image->height) return;
  std::uint8_t* p = image->at(x, y);
  p[0] = colour.r;
  p[1] = colour.g;
  p[2] = colour.b;
}

void fillRect(Image* image, int x0, int y0, int x1, int y1, Rgb colour) {
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) putPixel(image, x, y, colour);
  }
}

void drawLine(Image* image, int x0, int y0, int x1, int y1, Rgb colour, int width, int dash) {
  // Bresenham; a thick line is the same line stamped as a width x width square.
  const int dx = std::abs(x1 - x0);
  const int dy = -std::abs(y1 - y0);
  const int sx = x0 < x1 ? 1 : -1;
  const int sy = y0 < y1 ? 1 : -1;
  int err = dx + dy;
  for (int step = 0;; ++step) {
    if (dash <= 0 || (step / dash) % 2 == 0) {
      fillRect(image, x0 - width / 2, y0 - width / 2, x0 - width / 2 + width,
               y0 - width / 2 + width, colour);
    }
    if (x0 == x1 && y0 == y1) break;
    const int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x0 += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y0 += sy;
    }
  }
}

int textWidth(const std::string& text, int scale) {
  return static_cast<int>(text.size()) * 4 * scale;
}

int drawText(Image* image, int x, int y, const std::string& text, Rgb colour, int scale) {
  int cx = x;
  for (char ch : text) {
    const char lower = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
    const auto it = glyphs().find(lower);
    const char* g = it == glyphs().end() ? "###.#.#.#.#.###" : it->second;
    for (int r = 0; r < 5; ++r) {
      for (int c = 0; c < 3; ++c) {
        if (g[r * 3 + c] == '#') {
          fillRect(image, cx + c * scale, y + r * scale, cx + (c + 1) * scale, y + (r + 1) * scale,
                   colour);
        }
      }
    }
    cx += 4 * scale;
  }
  return cx - x;
}

}  // namespace sim
}  // namespace wavog
