#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <ostream>
#include <sstream>

namespace sdfg::demo {
namespace {

const char* kFingers[5] = {"thumb", "index", "middle", "ring", "little"};

// Non-finite numbers never reach the report: they print as a dash.
std::string num(float v, int decimals) {
  if (!std::isfinite(v)) return "-";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, double(v));
  // A value that rounds to zero is zero, whatever its sign.
  const std::string s = buf;
  return s.find_first_not_of("-0.") == std::string::npos && s[0] == '-' ? s.substr(1) : s;
}

// HTML text from the report's Markdown-style text: escaped, with `code` spans as <code>.
std::string inlineHtml(const std::string& s);

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    if (c == '<')
      out += "&lt;";
    else if (c == '>')
      out += "&gt;";
    else if (c == '&')
      out += "&amp;";
    else
      out += c;
  }
  return out;
}

std::string inlineHtml(const std::string& s) {
  std::string out;
  bool code = false;
  for (char c : s) {
    if (c == '`') {
      out += code ? "</code>" : "<code>";
      code = !code;
    } else {
      out += escape(std::string(1, c));
    }
  }
  if (code) out += "</code>";
  // A blank line is a paragraph break, as in the Markdown (callers wrap the text in <p>).
  for (size_t at = out.find("\n\n"); at != std::string::npos; at = out.find("\n\n", at))
    out.replace(at, 2, "</p>\n<p>");
  return out;
}

struct Row {
  std::vector<std::string> cells;
};

std::vector<std::string> header() {
  return {"strategy",
          "finger",
          "curl",
          "contact",
          "reported distance (mm)",
          "tip gap (mm)",
          "least clearance (mm)"};
}

std::vector<Row> rows(const ObjectResult& o) {
  std::vector<Row> out;
  for (const auto& s : o.strategies) {
    if (!s.ok) {
      out.push_back({{s.name, "-", "-", "-", "-", "-", "failed: " + s.error}});
      continue;
    }
    for (int f = 0; f < 5; ++f) {
      const FingerRow& r = s.fingers[f];
      out.push_back(
          {{s.name, kFingers[f], num(r.curl, 3), r.contact ? "yes" : "no",
            r.contact ? num(r.reportedMm, 2) : "-", num(r.tipGapMm, 2), num(r.clearanceMm, 2)}});
    }
  }
  return out;
}

std::string summaryLine(const StrategyResult& s) {
  std::ostringstream line;
  line << s.name << " (" << s.source << "): ";
  if (!s.ok) {
    line << "failed: " << s.error;
    return line.str();
  }
  float worst = 1e9f;
  for (const auto& f : s.fingers) worst = std::min(worst, f.clearanceMm);
  line << s.contacts << " fingers in contact, deepest finger point "
       << num(std::max(0.0f, -worst), 1) << " mm inside; whole hand "
       << (s.wholeHandMm >= 0.0f ? "clear (" + num(s.wholeHandMm, 2) + " mm)"
                                 : num(-s.wholeHandMm, 2) + " mm inside");
  if (s.source == "layer") {
    line << "; hand moved " << num(s.handMovedMm, 1) << " mm off the controller pose";
    if (s.openClearanceMm < 0.0f)
      line << " (the open hand was " << num(-s.openClearanceMm, 1) << " mm inside)";
  }
  if (s.source == "layer")
    line << ", grasp after " << s.frames << " frames (" << num(float(s.milliseconds), 1) << " ms)";
  else
    line << ", solved in " << num(float(s.milliseconds), 3) << " ms";
  return line.str();
}

const char* kExplain =
    "Each picture shows the same hand placement solved by three strategies, left to right: "
    "`physics-convex` (the physics-overlap method of commercial toolkits, fingertip spheres "
    "against the object's convex hull in Bullet, solved in-process by the core with the hand "
    "pose the layer used), `paper` (the paper's per-fingertip SDF sweep) and `ours` "
    "(whole-finger, conservative advancement, refined stop), the last two through OpenXR: the "
    "layer, the mock runtime's scripted controller, `xrLocateHandJointsEXT` and "
    "`xrGetGraspStateSDFG`. Object blue-grey, hand as capsules of its joint radii, contacts "
    "magenta (drawn on top). The slice is the grab-box SDF (built by the core's CPU builder at "
    "64^3 for the picture) in the middle finger's plane (blue "
    "inside, red outside, 1 cm isolines, surface black) with the `ours` hand in white.\n\n"
    "Columns: curl 0 open .. 1 closed; contact: the finger stopped on the surface; reported "
    "distance: what the strategy saw at its contact (SDF or Bullet); tip gap: exact distance "
    "of the fingertip sphere to the mesh (negative: inside); least clearance: the same for the "
    "whole finger (capsules of the joint radii), so a negative value is a finger through the "
    "object. Each strategy's line gives the whole hand's least clearance (palm, metacarpals "
    "and phalanges) and, for the layer's strategies, how far the layer moved the hand off the "
    "controller pose to clear the open hand before closing it (`XrGraspHandOffsetSDFG`; `ours` "
    "only).";

// A table in both forms: Markdown (the first two columns left-aligned) and HTML.
void writeTable(std::ostream& md, std::ostream& html, const std::vector<std::string>& head,
                const std::vector<Row>& body) {
  md << "|";
  html << "<div class=\"scroll\"><table><tr>";
  for (const auto& h : head) {
    md << " " << h << " |";
    html << "<th>" << escape(h) << "</th>";
  }
  md << "\n|";
  html << "</tr>\n";
  for (size_t i = 0; i < head.size(); ++i) md << (i < 2 ? "---|" : "---:|");
  md << "\n";
  for (const auto& r : body) {
    md << "|";
    html << "<tr>";
    for (const auto& c : r.cells) {
      md << " " << c << " |";
      html << "<td>" << escape(c) << "</td>";
    }
    md << "\n";
    html << "</tr>\n";
  }
  md << "\n";
  html << "</table></div>\n";
}

std::string depth(float clearanceMm) {
  return clearanceMm >= 0.0f ? "clear (" + num(clearanceMm, 2) + " mm)"
                             : num(-clearanceMm, 2) + " mm inside";
}

void writeScene(std::ostream& md, std::ostream& html, const SceneReport& scene) {
  md << "## Table scene\n\n" << scene.description << "\n\n";
  html << "<h2>Table scene</h2>\n<p>" << inlineHtml(scene.description) << "</p>\n";
  if (scene.png.empty()) {
    md << "The scene did not run (see above).\n\n";
    html << "<p class=\"fail\">The scene did not run (see above).</p>\n";
    return;
  }
  md << "![table scene: every grasp, then each close up](" << scene.png << ")\n\n";
  html << "<p><img src=\"" << scene.png << "\" alt=\"table scene\">\n<span class=\"caption\">"
       << "left: every grasp; then each close up</span></p>\n<ul>\n";
  for (const auto& g : scene.grasps) {
    std::string line = "hand placed on the " + g.aim + ": ";
    if (!g.ok)
      line += "failed: " + g.error;
    else
      line += "took the " + g.took + ", " + std::to_string(g.contacts) + " fingers in contact (" +
              std::to_string(g.fingersOnTaken) + " on the " + g.took +
              "); hand in the table: " + depth(g.tableMm) +
              "; in the objects: " + depth(g.objectsMm) + "; open hand moved " +
              num(g.handMovedMm, 1) + " mm; shown " + num(float(g.milliseconds), 0) +
              " ms after the squeeze";
    md << "- " << line << "\n";
    html << "<li>" << inlineHtml(line) << "</li>\n";
  }
  md << "\n";
  html << "</ul>\n";
  std::vector<Row> body;
  for (const auto& g : scene.grasps)
    for (int f = 0; f < 5 && g.ok; ++f)
      body.push_back({{g.aim, kFingers[f], num(g.curl[size_t(f)], 3), g.touched[size_t(f)]}});
  writeTable(md, html, {"placed on", "finger", "curl", "touches"}, body);
}

void writeOuter(std::ostream& md, std::ostream& html, const OuterReport& outer) {
  md << "## Outer hand\n\n" << outer.description << "\n\n";
  html << "<h2>Outer hand</h2>\n<p>" << inlineHtml(outer.description) << "</p>\n";
  if (outer.png.empty()) {
    md << "The sequence did not run (see above).\n\n";
    html << "<p class=\"fail\">The sequence did not run (see above).</p>\n";
    return;
  }
  const std::string line = "Deepest in the table: tracked hand " +
                           num(outer.deepestTrackedMm(), 1) + " mm, shown hand " +
                           num(outer.deepestShownMm(), 2) + " mm.";
  md << "![outer hand: tracked (top) and shown (bottom)](" << outer.png << ")\n\n"
     << line << "\n\n";
  html << "<p><img src=\"" << outer.png << "\" alt=\"outer hand\">\n<span class=\"caption\">"
       << "top: tracked hand; bottom: shown hand</span></p>\n<p>" << escape(line) << "</p>\n";
  std::vector<Row> body;
  for (const auto& f : outer.frames)
    body.push_back(
        {{std::to_string(f.frame) + (f.pictured ? " (pictured)" : ""), f.phase, num(f.trackedMm, 2),
          num(f.shownMm, 2), num(f.offsetMm, 1), f.constrained ? "yes" : "no"}});
  writeTable(md, html,
             {"frame", "phase", "tracked clearance (mm)", "shown clearance (mm)",
              "shown wrist off tracked (mm)", "constrained"},
             body);
}

}  // namespace

float OuterReport::deepestTrackedMm() const {
  float least = 0.0f;
  for (const OuterFrameRow& f : frames) least = std::min(least, f.trackedMm);
  return std::max(0.0f, -least);  // not -0
}

float OuterReport::deepestShownMm() const {
  float least = 0.0f;
  for (const OuterFrameRow& f : frames) least = std::min(least, f.shownMm);
  return std::max(0.0f, -least);  // not -0
}

bool writeReports(const std::string& dir, const std::vector<ObjectResult>& objects,
                  const SceneReport& scene, const OuterReport& outer, const ReportInfo& info,
                  std::string& error) {
  std::ofstream md(dir + "/report.md");
  std::ofstream html(dir + "/report.html");
  if (!md || !html) {
    error = dir + ": cannot write report.md / report.html";
    return false;
  }
  md << "# SDF Autograsp demo\n\n" << kExplain << "\n\n";
  md << "Runtime: " << info.runtime << "; Vulkan device: " << info.device << "; "
     << info.environment << "; panel width " << info.width << " px.\n\n";
  md << "Code: git commit " << info.commit << ".\n\n";
  html << "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>SDF Autograsp demo</title>"
       << "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
       // Pictures and tables shrink to the page (a picture row is three panels wide), text is
       // set at a readable measure, and code spans look like code.
       << "<style>body{font-family:sans-serif;max-width:1200px;margin:auto;padding:0 16px;"
       << "background:#fafafa;line-height:1.45;color:#222}p,li{max-width:80ch}"
       << "img{display:block;max-width:100%;height:auto;border:1px solid #ccc}"
       << "img.slice{max-width:min(100%,512px)}.scroll{overflow-x:auto}"
       << "table{border-collapse:collapse;margin:8px 0;font-size:0.9em}"
       << "td,th{border:1px solid #bbb;padding:2px 8px;text-align:right}"
       << "th{background:#eee}td:first-child,td:nth-child(2),th:first-child,th:nth-child(2)"
       << "{text-align:left}.caption{font-size:0.85em;color:#555}"
       << "code{font-family:monospace;background:#eee;padding:0 3px;border-radius:3px}"
       << ".fail{color:#b00}</style></head><body>\n"
       << "<h1>SDF Autograsp demo</h1>\n<p>" << inlineHtml(kExplain)
       << "</p>\n<p>Runtime: " << escape(info.runtime) << "; Vulkan device: " << escape(info.device)
       << "; " << escape(info.environment) << "; panel width " << info.width << " px.</p>\n"
       << "<p>Code: git commit " << escape(info.commit) << ".</p>\n";
  if (!info.failures.empty()) {
    md << "## Skipped\n\n";
    html << "<h2>Skipped</h2><ul>\n";
    for (const auto& f : info.failures) {
      md << "- " << f << "\n";
      html << "<li class=\"fail\">" << escape(f) << "</li>\n";
    }
    md << "\n";
    html << "</ul>\n";
  }
  for (const auto& o : objects) {
    md << "## " << o.name << "\n\n" << o.origin << ", " << o.triangles << " triangles.\n\n";
    md << "![" << o.name << ": physics-convex, paper, ours](" << o.graspPng << ")\n\n";
    md << "![" << o.name << ": grab-box SDF slice](" << o.slicePng << ")\n\n";
    html << "<h2>" << escape(o.name) << "</h2>\n<p>" << escape(o.origin) << ", " << o.triangles
         << " triangles.</p>\n<p><img src=\"" << o.graspPng << "\" alt=\"" << escape(o.name)
         << ": physics-convex, paper, ours\">\n<span class=\"caption\">left to right: "
         << "<code>physics-convex</code>, <code>paper</code>, <code>ours</code></span></p>\n"
         << "<p><img src=\"" << o.slicePng
         << "\" alt=\"grab-box SDF slice\" class=\"slice\"></p>\n<ul>\n";
    for (const auto& s : o.strategies) {
      md << "- " << summaryLine(s) << "\n";
      html << "<li>" << inlineHtml(summaryLine(s)) << "</li>\n";
    }
    md << "\n";
    html << "</ul>\n";
    writeTable(md, html, header(), rows(o));
  }
  writeScene(md, html, scene);
  writeOuter(md, html, outer);
  html << "</body></html>\n";
  if (!md || !html) {
    error = dir + ": writing the report failed";
    return false;
  }
  return true;
}

}  // namespace sdfg::demo
