// autograsp-demo-check: checks what autograsp-demo wrote, for the demo test.
//   autograsp-demo-check DIR WIDTH OBJECT...
// Per object: <object>-grasp.png is (3 * WIDTH + 8) x WIDTH, each of its three panels holds many
// colours, the object's blue-grey and the hand's skin tone, and the image has contact magenta;
// <object>-sdf-slice.png is WIDTH x WIDTH with inside blue, outside red and the black surface.
// table-scene.png is 4 panels of WIDTH (4 px apart: the scene, then each of its 3 grasps) with the
// hand, the objects, the table and contacts in every panel; outer-hand.png is 5 x 2 panels of WIDTH
// / 2 (4 px apart), the tracked hand grey in the top row and the shown hand in skin tone in the
// bottom one. report.md and report.html exist, show every picture, have 15 finger rows per object
// (before the table scene) and no non-finite number, and name the commit of the code that made
// them; the outer hand's tracked hand goes more than 2 cm into the table and the shown one less
// than 1 mm. Prints each failed check; exit status 1 when any failed.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "png_io.h"

namespace {

int failures = 0;

void check(bool ok, const std::string& what) {
  if (!ok) {
    std::printf("FAIL: %s\n", what.c_str());
    ++failures;
  } else {
    std::printf("ok:   %s\n", what.c_str());
  }
}

struct Counts {
  std::set<uint32_t> colours;
  size_t hand = 0, object = 0, magenta = 0, blue = 0, red = 0, black = 0, pixels = 0, table = 0,
         grey = 0;
};

// Over columns [x0, x1) of rows [y0, y0 + height) of a picture `width` pixels wide.
Counts count(const std::vector<uint8_t>& rgba, uint32_t width, uint32_t x0, uint32_t x1,
             uint32_t height, uint32_t y0 = 0) {
  Counts c;
  for (uint32_t y = y0; y < y0 + height; ++y) {
    for (uint32_t x = x0; x < x1; ++x) {
      const uint8_t* p = &rgba[(size_t(y) * width + x) * 4];
      const int r = p[0], g = p[1], b = p[2];
      c.colours.insert(uint32_t(r) << 16 | uint32_t(g) << 8 | uint32_t(b));
      ++c.pixels;
      if (r > g + 15 && g > b + 15 && r > 90) ++c.hand;          // skin: r > g > b
      if (b > r + 15 && b >= g && b > 60 && r > 40) ++c.object;  // blue-grey
      if (r == 255 && g == 0 && b == 255) ++c.magenta;           // contacts
      if (b > r + 40) ++c.blue;
      if (r > b + 40) ++c.red;
      if (r < 8 && g < 8 && b < 8) ++c.black;
      if (g > r + 5 && g > b + 10 && g > 60) ++c.table;  // grey-green
      if (std::abs(r - g) < 6 && b >= g && b - g < 10 && r > 40) ++c.grey;
    }
  }
  return c;
}

std::string slurp(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool hasNonFinite(const std::string& text) {
  std::string lower;
  for (char ch : text) lower += char(std::tolower(static_cast<unsigned char>(ch)));
  for (const char* bad : {"nan", "inf"}) {
    for (size_t at = lower.find(bad); at != std::string::npos; at = lower.find(bad, at + 1)) {
      // A whole word only ("infinite" or "information" in prose is fine).
      const bool startOk = at == 0 || !std::isalpha(static_cast<unsigned char>(lower[at - 1]));
      const size_t end = at + 3;
      const bool endOk =
          end >= lower.size() || !std::isalpha(static_cast<unsigned char>(lower[end]));
      if (startOk && endOk) return true;
    }
  }
  return false;
}

bool readPicture(const std::string& dir, const std::string& png, uint32_t wantW, uint32_t wantH,
                 std::vector<uint8_t>& rgba) {
  uint32_t pw = 0, ph = 0;
  std::string error;
  const bool read = sdfg::demo::readPng(dir + "/" + png, pw, ph, rgba, error);
  check(read, png + " readable " + error);
  if (!read) return false;
  const bool sized = pw == wantW && ph == wantH;
  check(sized, png + " is " + std::to_string(wantW) + "x" + std::to_string(wantH) + " (got " +
                   std::to_string(pw) + "x" + std::to_string(ph) + ")");
  return sized;
}

void checkShown(const std::string& png, const std::string& md, const std::string& html) {
  check(md.find("(" + png + ")") != std::string::npos, "report.md shows " + png);
  check(html.find("src=\"" + png + "\"") != std::string::npos, "report.html shows " + png);
}

void checkScene(const std::string& dir, uint32_t w, const std::string& md,
                const std::string& html) {
  const std::string png = "table-scene.png";
  checkShown(png, md, html);
  std::vector<uint8_t> rgba;
  constexpr uint32_t kPanels = 4;
  if (!readPicture(dir, png, kPanels * w + (kPanels - 1) * 4, w, rgba)) return;
  for (uint32_t p = 0; p < kPanels; ++p) {
    const Counts c = count(rgba, kPanels * w + (kPanels - 1) * 4, p * (w + 4), p * (w + 4) + w, w);
    const std::string name = "table scene panel " + std::to_string(p);
    check(c.hand > c.pixels / 100, name + ": hand colour on " + std::to_string(c.hand) + " px");
    check(c.object > c.pixels / 200,
          name + ": object colour on " + std::to_string(c.object) + " px");
    check(c.table > c.pixels / 50, name + ": table colour on " + std::to_string(c.table) + " px");
    check(c.magenta > 0, name + ": contact markers (" + std::to_string(c.magenta) + " px)");
  }
}

void checkOuter(const std::string& dir, uint32_t w, const std::string& md,
                const std::string& html) {
  const std::string png = "outer-hand.png";
  checkShown(png, md, html);
  const uint32_t p = w / 2, totalW = 5 * p + 16, totalH = 2 * p + 4;
  std::vector<uint8_t> rgba;
  if (readPicture(dir, png, totalW, totalH, rgba)) {
    for (uint32_t col = 0; col < 5; ++col) {
      const uint32_t x0 = col * (p + 4);
      const Counts top = count(rgba, totalW, x0, x0 + p, p);
      const Counts bottom = count(rgba, totalW, x0, x0 + p, p, p + 4);
      const std::string name = "outer hand column " + std::to_string(col);
      check(top.grey > top.pixels / 200 && top.hand == 0,
            name + ": tracked hand grey (" + std::to_string(top.grey) + " px), no skin tone");
      check(bottom.hand > bottom.pixels / 200,
            name + ": shown hand in skin tone on " + std::to_string(bottom.hand) + " px");
      check(top.table > top.pixels / 50 && bottom.table > bottom.pixels / 50,
            name + ": the table in both rows");
    }
  }
  // The point of the outer hand, from the report's own numbers.
  std::smatch m;
  const std::regex deepest(
      "Deepest in the table: tracked hand ([0-9.]+) mm, shown hand ([0-9.]+) mm");
  const bool found = std::regex_search(md, m, deepest);
  check(found, "report.md gives the deepest tracked and shown hand");
  if (found) {
    const double tracked = std::stod(m[1]), shown = std::stod(m[2]);
    check(tracked > 20.0, "the tracked hand goes " + m[1].str() + " mm into the table (> 20)");
    check(shown < 1.0, "the shown hand goes " + m[2].str() + " mm into the table (< 1)");
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 4) {
    std::fprintf(stderr, "usage: autograsp-demo-check DIR WIDTH OBJECT...\n");
    return 2;
  }
  const std::string dir = argv[1];
  const uint32_t w = uint32_t(std::atoi(argv[2]));
  std::vector<std::string> objects(argv + 3, argv + argc);
  const std::string md = slurp(dir + "/report.md"), html = slurp(dir + "/report.html");
  check(!md.empty(), "report.md present");
  check(!html.empty() && html.find("</html>") != std::string::npos, "report.html present");
  check(!hasNonFinite(md) && !hasNonFinite(html), "no nan or inf in the reports");
  // The code that made them: a full commit hash, or "unknown" outside a git checkout.
  const std::regex commit("Code: git commit ([0-9a-f]{40} \\(|unknown )");
  check(std::regex_search(md, commit) && std::regex_search(html, commit),
        "the reports name the commit of the code");
  size_t rows = 0;
  const size_t sceneAt = md.find("\n## Table scene");
  check(sceneAt != std::string::npos, "report.md has the table scene");
  check(md.find("\n## Outer hand") != std::string::npos, "report.md has the outer hand");
  for (size_t at = md.find("\n| "); at < sceneAt; at = md.find("\n| ", at + 1)) ++rows;
  // One header row per object, then 5 fingers x 3 strategies.
  check(rows == objects.size() * 16,
        "report.md: 15 finger rows per object (" + std::to_string(rows) + " table rows)");
  for (const auto& o : objects) {
    for (const std::string& png : {o + "-grasp.png", o + "-sdf-slice.png"})
      checkShown(png, md, html);
    std::vector<uint8_t> rgba;
    if (readPicture(dir, o + "-grasp.png", 3 * w + 8, w, rgba)) {
      size_t magenta = 0;
      for (uint32_t p = 0; p < 3; ++p) {
        const Counts c = count(rgba, 3 * w + 8, p * (w + 4), p * (w + 4) + w, w);
        const std::string name = o + " panel " + std::to_string(p);
        check(c.colours.size() > 200, name + ": " + std::to_string(c.colours.size()) + " colours");
        check(c.hand > c.pixels / 100, name + ": hand colour on " + std::to_string(c.hand) + " px");
        check(c.object > c.pixels / 200,
              name + ": object colour on " + std::to_string(c.object) + " px");
        magenta += c.magenta;
      }
      check(magenta > 0, o + ": contact markers (" + std::to_string(magenta) + " px)");
    }
    if (readPicture(dir, o + "-sdf-slice.png", w, w, rgba)) {
      const Counts c = count(rgba, w, 0, w, w);
      check(c.blue > 0 && c.red > c.pixels / 4 && c.black > 0,
            o + " slice: inside blue, outside red, black surface");
    }
  }
  checkScene(dir, w, md, html);
  checkOuter(dir, w, md, html);
  std::printf("%s: %d failed checks\n", failures == 0 ? "PASS" : "FAIL", failures);
  return failures == 0 ? 0 : 1;
}
