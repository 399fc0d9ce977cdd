#include "render/scene_labels.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "render/tendon_heat.h"

namespace recruit::render {

int TextWidth(const std::string& s, const mjrContext* con) {
  int w = 0;
  for (unsigned char c : s)
    w += c < 127 ? con->charWidth[c] : con->charWidth[static_cast<unsigned char>('?')];
  return w;
}

std::optional<Pixel> ProjectToViewport(const mjvScene& scene, mjrRect viewport, const double p[3]) {
  const mjvGLCamera cam = mjv_averageCamera(&scene.camera[0], &scene.camera[1]);
  const double f[3] = {cam.forward[0], cam.forward[1], cam.forward[2]};
  const double u[3] = {cam.up[0], cam.up[1], cam.up[2]};
  const double r[3] = {f[1] * u[2] - f[2] * u[1], f[2] * u[0] - f[0] * u[2],
                       f[0] * u[1] - f[1] * u[0]};
  const double v[3] = {p[0] - cam.pos[0], p[1] - cam.pos[1], p[2] - cam.pos[2]};
  const double z = v[0] * f[0] + v[1] * f[1] + v[2] * f[2];
  const double x = v[0] * r[0] + v[1] * r[1] + v[2] * r[2];
  const double y = v[0] * u[0] + v[1] * u[1] + v[2] * u[2];
  if (!cam.orthographic && z <= cam.frustum_near) return std::nullopt;
  // mjr_render's frustum: [center -+ halfwidth] x [bottom, top] at the near plane, halfwidth
  // from the viewport's aspect unless the camera fixes it.
  const double aspect = static_cast<double>(viewport.width) / std::max(1, viewport.height);
  const double half = cam.frustum_width > 0 ? cam.frustum_width
                                            : 0.5 * aspect * (cam.frustum_top - cam.frustum_bottom);
  const double s = cam.orthographic ? 1.0 : cam.frustum_near / z;
  const double xn = (x * s - (cam.frustum_center - half)) / (2 * half);
  const double yn = (y * s - cam.frustum_bottom) / (cam.frustum_top - cam.frustum_bottom);
  return Pixel{xn * viewport.width, yn * viewport.height};
}

std::vector<TendonLabel> PlaceTendonLabels(const mjModel* m, const mjData* d, const mjvScene& scene,
                                           mjrRect viewport, const TelemetrySample& sample,
                                           const std::vector<std::optional<UnitCounts>>& counts) {
  std::vector<TendonLabel> labels;
  std::vector<double> mean_x;  // projected x of each tendon's first segment
  const int n = static_cast<int>(sample.bundles.size());
  for (int b = 0; b < n; ++b) {
    const BundleTelemetry& bt = sample.bundles[b];
    const int t = bt.tendon_id;
    if (t < 0 || t >= m->ntendon || d->ten_wrapnum[t] < 2) continue;
    const double* p0 = d->wrap_xpos + 3 * d->ten_wrapadr[t];
    const double* p1 = p0 + 3;
    const double f = (b + 1.0) / (n + 1.0);
    const double a[3] = {p0[0] + f * (p1[0] - p0[0]), p0[1] + f * (p1[1] - p0[1]),
                         p0[2] + f * (p1[2] - p0[2])};
    const double mid[3] = {0.5 * (p0[0] + p1[0]), 0.5 * (p0[1] + p1[1]), 0.5 * (p0[2] + p1[2])};
    auto pa = ProjectToViewport(scene, viewport, a);
    auto pm = ProjectToViewport(scene, viewport, mid);
    if (!pa || !pm) continue;
    char text[160];
    std::snprintf(text, sizeof(text), "%s %.0f C", bt.actuator.c_str(), bt.mean_temperature);
    if (b < static_cast<int>(counts.size()) && counts[b]) {
      std::snprintf(text, sizeof(text), "%s %.0f C, %d/%d working", bt.actuator.c_str(),
                    bt.mean_temperature, counts[b]->working, counts[b]->total());
    }
    labels.push_back({text, *pa, false});
    mean_x.push_back(pm->x);
  }
  if (labels.size() > 1) {
    const size_t leftmost = std::min_element(mean_x.begin(), mean_x.end()) - mean_x.begin();
    labels[leftmost].left = true;
  }
  return labels;
}

void DrawTendonLabels(const std::vector<TendonLabel>& labels, mjrRect viewport,
                      const mjrContext* con) {
  const int ch = con->charHeight;
  for (const TendonLabel& l : labels) {
    const int w = TextWidth(l.text, con) + ch / 2;
    const int h = ch + ch / 4;
    const int ax = viewport.left + static_cast<int>(std::lround(l.anchor.x));
    const int ay = viewport.bottom + static_cast<int>(std::lround(l.anchor.y));
    const int gap = 2 * ch;
    int x = l.left ? ax - gap - w : ax + gap;
    x = std::clamp(x, viewport.left, viewport.left + viewport.width - w);
    const int y = std::clamp(ay - h / 2, viewport.bottom, viewport.bottom + viewport.height - h);
    const int lw = std::max(1, ch / 10);
    // Leader from the tendon to the box.
    const int x0 = std::min(ax, l.left ? x + w : x), x1 = std::max(ax, l.left ? x + w : x);
    mjr_rectangle({x0, ay - lw / 2, std::max(1, x1 - x0), lw}, 0.1f, 0.1f, 0.1f, 0.9f);
    mjr_label({x, y, w, h}, mjFONT_NORMAL, l.text.c_str(), 0.1f, 0.1f, 0.12f, 0.8f, 1.f, 1.f, 1.f,
              con);
  }
}

int HeatKeyHeight(const mjrContext* con, int rows) {
  const int ch = con->charHeight;
  return (2 + rows) * (ch + ch / 4) + std::max(4, ch / 2) + 2 * (ch / 4);
}

std::vector<std::string> HeatKeyRows(const TelemetrySample& sample,
                                     const std::vector<std::optional<UnitCounts>>& counts) {
  std::vector<std::string> rows;
  for (size_t b = 0; b < sample.bundles.size() && b < counts.size(); ++b) {
    if (counts[b]) rows.push_back(sample.bundles[b].actuator + ": " + WorkingText(*counts[b]));
  }
  return rows;
}

int DrawHeatKey(int left, int top, int width, const mjrContext* con,
                const std::vector<std::string>& rows) {
  const int ch = con->charHeight;
  const int row = ch + ch / 4;
  const int bar = std::max(4, ch / 2);
  const int pad = ch / 4;
  const std::string title = "tendon heat";
  const std::string lo = "ambient", hi = "on-state";
  width = std::max(width, TextWidth(lo + "  " + hi, con) + 2 * pad);
  for (const std::string& r : rows) width = std::max(width, TextWidth(r, con) + 2 * pad);
  const int height = HeatKeyHeight(con, static_cast<int>(rows.size()));
  mjr_rectangle({left, top - height, width, height}, 0.1f, 0.1f, 0.12f, 0.75f);
  mjr_label({left + pad, top - pad - row, TextWidth(title, con), row}, mjFONT_NORMAL, title.c_str(),
            0, 0, 0, 0, 1, 1, 1, con);
  const int bar_top = top - pad - row;
  const int steps = 32;
  const int inner = width - 2 * pad;
  for (int k = 0; k < steps; ++k) {
    const std::array<float, 4> c = HeatColour((k + 0.5) / steps);
    const int x0 = left + pad + inner * k / steps, x1 = left + pad + inner * (k + 1) / steps;
    mjr_rectangle({x0, bar_top - bar, x1 - x0, bar}, c[0], c[1], c[2], 1.f);
  }
  const int label_y = bar_top - bar - row;
  mjr_label({left + pad, label_y, TextWidth(lo, con), row}, mjFONT_NORMAL, lo.c_str(), 0, 0, 0, 0,
            0.85f, 0.85f, 0.85f, con);
  mjr_label({left + width - pad - TextWidth(hi, con), label_y, TextWidth(hi, con), row},
            mjFONT_NORMAL, hi.c_str(), 0, 0, 0, 0, 0.85f, 0.85f, 0.85f, con);
  // The units still working of each bundle whose units can fail (working vs total).
  for (size_t i = 0; i < rows.size(); ++i) {
    const int y = label_y - static_cast<int>(i + 1) * row;
    mjr_label({left + pad, y, TextWidth(rows[i], con), row}, mjFONT_NORMAL, rows[i].c_str(), 0, 0,
              0, 0, 1.f, 0.85f, 0.4f, con);
  }
  return height;
}

}  // namespace recruit::render
