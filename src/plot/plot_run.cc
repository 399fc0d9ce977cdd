#include "plot/plot_run.h"

#include <fmt/format.h>

#include <filesystem>
#include <sstream>

#include "common/atomic_file.h"
#include "common/short_text.h"
#include "plot/column_figure.h"
#include "plot/render.h"
#include "plot/run_data.h"
#include "plot/run_figures.h"
#include "plot/stability_map.h"

namespace recruit::plot {
namespace {

namespace fs = std::filesystem;

Result<std::vector<Format>> ParseFormats(const std::string& list) {
  std::vector<Format> out;
  std::istringstream in(list);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (item == "png")
      out.push_back(Format::kPng);
    else if (item == "svg")
      out.push_back(Format::kSvg);
    else
      return Error{fmt::format("--format: '{}' is not allowed (png, svg, or both: png,svg)",
                               ShortText(item))};
  }
  if (out.empty()) return Error{"--format: empty (png, svg, or both: png,svg)"};
  return out;
}

Status CheckSize(const char* option, int value, int min) {
  if (value >= min && value <= kMaxSide) return Status::Ok();
  return Error{
      fmt::format("{}: {} px is out of range ({}..{} px allowed)", option, value, min, kMaxSide)};
}

std::string DefaultName(const std::string& csv) {
  std::string stem = fs::path(csv).filename().string();
  for (const std::string suffix : {".csv", "_steps"}) {
    if (stem.size() > suffix.size() &&
        stem.compare(stem.size() - suffix.size(), suffix.size(), suffix) == 0) {
      stem.resize(stem.size() - suffix.size());
    }
  }
  return stem;
}

struct Rendered {
  std::string path, bytes;
};

// Everything rendered: only now touch the disk.
Result<std::vector<std::string>> WriteAll(const std::string& out_dir,
                                          const std::vector<Rendered>& files) {
  std::error_code ec;
  fs::create_directories(out_dir, ec);
  if (ec)
    return Error{
        fmt::format("--out: cannot create directory '{}': {}", ShortText(out_dir), ec.message()),
        ErrorCode::kIo};
  std::vector<std::string> written;
  for (const Rendered& r : files) {
    if (Status s = WriteFileAtomically(r.path, r.bytes); !s.ok()) return Error{s.error(), s.code()};
    written.push_back(r.path);
  }
  return written;
}

}  // namespace

Result<std::vector<std::string>> RunPlot(const PlotOptions& o) {
  auto formats = ParseFormats(o.formats);
  if (!formats.ok()) return Error{formats.error(), formats.code()};
  for (Status s :
       {CheckSize("--width", o.width, kMinWidth), CheckSize("--height", o.height, kMinHeight)}) {
    if (!s.ok()) return Error{s.error(), s.code()};
  }
  if (o.out_dir.empty()) return Error{"--out: empty (a directory for the figures)"};
  std::vector<Rendered> files;
  if (!o.stability_map.empty()) {
    auto text = ReadFile(o.stability_map);
    if (!text.ok()) return Error{text.error(), text.code()};
    auto panels = ParseStabilityDat(*text, o.stability_map);
    if (!panels.ok()) return Error{panels.error(), panels.code()};
    const std::string map_name = o.name.empty() ? "stability" : o.name;
    const std::string title =
        o.title.empty() ? "mean step overshoot (%), ring = meets the sweep's criterion" : o.title;
    for (Format fmt : *formats) {
      auto bytes = RenderStabilityMap(*panels, title, o.width, o.height, fmt);
      if (!bytes.ok()) return Error{bytes.error(), bytes.code()};
      const char* ext = fmt == Format::kPng ? "png" : "svg";
      files.push_back({(fs::path(o.out_dir) / fmt::format("{}.{}", map_name, ext)).string(),
                       std::move(*bytes)});
    }
    return WriteAll(o.out_dir, files);
  }
  const std::string name = o.name.empty() ? DefaultName(o.csv) : o.name;
  if (!o.panels.empty()) {
    std::vector<PanelSpec> specs;
    for (const std::string& p : o.panels) {
      auto spec = ParsePanelSpec(p);
      if (!spec.ok()) return Error{spec.error(), spec.code()};
      specs.push_back(*spec);
    }
    auto table = ReadCsvTable(o.csv);
    if (!table.ok()) return Error{table.error(), table.code()};
    auto fig = MakeColumnFigure(*table, o.x, o.x_label, specs, o.title);
    if (!fig.ok()) return Error{fig.error(), fig.code()};
    const double per_panel = specs.size() == 1 ? 1.0 : o.width < 640 ? 1.0 : 0.55;
    const int h = std::min(kMaxSide, static_cast<int>(per_panel * specs.size() * o.height));
    for (Format fmt : *formats) {
      auto bytes = RenderFigure(*fig, o.width, h, fmt);
      if (!bytes.ok()) return Error{bytes.error(), bytes.code()};
      const char* ext = fmt == Format::kPng ? "png" : "svg";
      files.push_back(
          {(fs::path(o.out_dir) / fmt::format("{}.{}", name, ext)).string(), std::move(*bytes)});
    }
    return WriteAll(o.out_dir, files);
  }
  auto csv = ReadRunCsv(o.csv);
  if (!csv.ok()) return Error{csv.error(), csv.code()};
  RunInfo info;
  if (!o.summary.empty()) {
    auto s = ReadRunSummary(o.summary);
    if (!s.ok()) return Error{s.error(), s.code()};
    info = *s;
  }
  const std::vector<NamedFigure> figures = MakeRunFigures(*csv, info);
  if (!o.figure.empty()) {
    std::string names;
    bool known = false;
    for (const NamedFigure& f : figures) {
      names += (names.empty() ? "" : ", ") + f.name;
      known = known || f.name == o.figure;
    }
    if (!known) {
      return Error{fmt::format("--figure: '{}' is not a figure of this run ({})",
                               ShortText(o.figure), names)};
    }
  }
  for (const NamedFigure& f : figures) {
    if (!o.figure.empty() && f.name != o.figure) continue;
    // The combined figure gives each panel 55 % of a single figure's height, or all of it on a
    // narrow canvas, where each legend goes below its panel.
    const double per_panel = o.width < 640 ? 1.0 : 0.55;
    const double scale = f.name == "all" ? per_panel * f.figure.panels.size() : 1.0;
    const int h = std::min(kMaxSide, static_cast<int>(scale * o.height));
    for (Format fmt : *formats) {
      auto bytes = RenderFigure(f.figure, o.width, h, fmt);
      if (!bytes.ok())
        return Error{fmt::format("figure '{}': {}", f.name, bytes.error()), bytes.code()};
      const char* ext = fmt == Format::kPng ? "png" : "svg";
      const std::string file = o.figure.empty() ? fmt::format("{}_{}.{}", name, f.name, ext)
                                                : fmt::format("{}.{}", name, ext);
      files.push_back({(fs::path(o.out_dir) / file).string(), std::move(*bytes)});
    }
  }
  return WriteAll(o.out_dir, files);
}

}  // namespace recruit::plot
