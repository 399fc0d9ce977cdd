#include "render/telemetry_plots.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>

namespace recruit::render {
namespace {

void Style(mjvFigure* fig) {
  mjv_defaultFigure(fig);
  fig->flg_legend = 1;
  fig->flg_extend = 1;
  fig->flg_ticklabel[0] = 1;
  fig->flg_ticklabel[1] = 1;
  fig->linewidth = 2.f;
  fig->gridsize[0] = 5;
  fig->gridsize[1] = 5;
  // Translucent dark background so the scene shows through.
  const float figure[4] = {0.05f, 0.05f, 0.08f, 0.75f};
  std::memcpy(fig->figurergba, figure, sizeof(figure));
  const float pane[4] = {0.10f, 0.10f, 0.14f, 0.6f};
  std::memcpy(fig->panergba, pane, sizeof(pane));
  const float legend[4] = {0.f, 0.f, 0.f, 0.4f};
  std::memcpy(fig->legendrgba, legend, sizeof(legend));
  std::snprintf(fig->xformat, sizeof(fig->xformat), "%%.0f");
  std::snprintf(fig->yformat, sizeof(fig->yformat), "%%.3g");
  std::snprintf(fig->minwidth, sizeof(fig->minwidth), "00000");
  std::snprintf(fig->xlabel, sizeof(fig->xlabel), "time (s)");
}

void SetLine(mjvFigure* fig, int line, const char* name, float r, float g, float b) {
  std::snprintf(fig->linename[line], sizeof(fig->linename[line]), "%s", name);
  fig->linergb[line][0] = r;
  fig->linergb[line][1] = g;
  fig->linergb[line][2] = b;
}

// Distinct colours per bundle: true count solid, estimate a lighter shade of the same hue.
constexpr float kBundleRgb[TelemetryPlots::kMaxBundles][3] = {
    {1.0f, 0.55f, 0.1f}, {0.3f, 0.8f, 1.0f}, {0.6f, 1.0f, 0.3f}, {1.0f, 0.4f, 0.8f}};

}  // namespace

TelemetryPlots::TelemetryPlots(double window)
    : window_(window > 0 ? window : 20.0),
      tracking_(std::make_unique<mjvFigure>()),
      recruitment_(std::make_unique<mjvFigure>()) {
  Style(tracking_.get());
  Style(recruitment_.get());
  std::snprintf(tracking_->title, sizeof(tracking_->title), "tracking");
  std::snprintf(tracking_->yformat, sizeof(tracking_->yformat), "%%.1f");
  std::snprintf(recruitment_->yformat, sizeof(recruitment_->yformat), "%%.1f");
  // y starts at [0, 1] and extends to fit the data (flg_extend), so a flat start (nothing on
  // yet) gets readable ticks instead of MuJoCo's minimum range of 1e-5.
  for (mjvFigure* fig : {tracking_.get(), recruitment_.get()}) {
    fig->range[1][0] = 0;
    fig->range[1][1] = 1;
  }
  std::snprintf(recruitment_->title, sizeof(recruitment_->title), "units on (pale: estimated)");
  SetLine(tracking_.get(), 0, "reference", 1.f, 1.f, 1.f);
  SetLine(tracking_.get(), 1, "measured", 1.f, 0.35f, 0.2f);
}

void TelemetryPlots::Push(mjvFigure* fig, int line, double x, double y) {
  if (!std::isfinite(x) || !std::isfinite(y)) return;
  int& n = fig->linepnt[line];
  float* data = fig->linedata[line];
  if (n == mjMAXLINEPNT) {  // full: drop the oldest point
    std::memmove(data, data + 2, sizeof(float) * 2 * (mjMAXLINEPNT - 1));
    --n;
  }
  data[2 * n] = static_cast<float>(x);
  data[2 * n + 1] = static_cast<float>(y);
  ++n;
}

void TelemetryPlots::Scroll(mjvFigure* fig, double now) {
  const double start = now - window_;
  for (int line = 0; line < mjMAXLINE; ++line) {
    int& n = fig->linepnt[line];
    int drop = 0;
    while (drop < n && fig->linedata[line][2 * drop] < start) ++drop;
    if (drop > 0) {
      std::memmove(fig->linedata[line], fig->linedata[line] + 2 * drop,
                   sizeof(float) * 2 * (n - drop));
      n -= drop;
    }
  }
  // Fixed x range: the window ends at `now`, so the plot scrolls instead of rescaling.
  fig->range[0][0] = static_cast<float>(std::max(0.0, start));
  fig->range[0][1] = static_cast<float>(std::max(now, window_));
}

void TelemetryPlots::Add(const TelemetrySample& s) {
  if (!configured_) {
    configured_ = true;
    angle_ = s.reference_unit == "rad";
    std::snprintf(tracking_->title, sizeof(tracking_->title), "%s",
                  angle_ ? "joint angle (deg)" : "force (N)");
    const int nb = std::min<int>(s.bundles.size(), kMaxBundles);
    for (int b = 0; b < nb; ++b) {
      const float* c = kBundleRgb[b];
      // The legend names the bundles (true counts); estimates are the paler, unnamed lines
      // (mjr_figure leaves unnamed lines out of the legend).
      SetLine(recruitment_.get(), 2 * b, nb > 1 ? s.bundles[b].actuator.c_str() : "true", c[0],
              c[1], c[2]);
      SetLine(recruitment_.get(), 2 * b + 1, nb > 1 ? "" : "estimated", 0.55f + 0.45f * c[0],
              0.55f + 0.45f * c[1], 0.55f + 0.45f * c[2]);
    }
  }
  // Angles are plotted in degrees, the unit task files use.
  const double scale = angle_ ? 180.0 / M_PI : 1.0;
  Push(tracking_.get(), 0, s.time, scale * s.reference);
  Push(tracking_.get(), 1, s.time, scale * s.measured);
  const int nb = std::min<int>(s.bundles.size(), kMaxBundles);
  for (int b = 0; b < nb; ++b) {
    Push(recruitment_.get(), 2 * b, s.time, s.bundles[b].true_on);
    Push(recruitment_.get(), 2 * b + 1, s.time, s.bundles[b].estimated_on);
  }
  Scroll(tracking_.get(), s.time);
  Scroll(recruitment_.get(), s.time);
}

void TelemetryPlots::Draw(mjrRect area, const mjrContext* con) {
  const int half = area.height / 2;
  mjrRect top = {area.left, area.bottom + half, area.width, area.height - half};
  mjrRect bottom = {area.left, area.bottom, area.width, half};
  mjr_figure(top, tracking_.get(), con);
  mjr_figure(bottom, recruitment_.get(), con);
}

}  // namespace recruit::render
