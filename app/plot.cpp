// Sweep CSV and plots. VTK 9.1 on Debian is built for X only; it renders here inside our own EGL context
// through a vtkGenericOpenGLRenderWindow whose GLEW check tolerates the missing GLX display (the fix in
// ../shared/notes/platform.md, section g). This file must not include glad (pvrr/gl/gl.h).
#include "app/plot.h"

#include <vtk_glew.h>
#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkCallbackCommand.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkContext2D.h>
#include <vtkPoints2D.h>
#include <vtkTransform2D.h>
#include <vtkRect.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

#include "app/commands.h"
#include "pvrr/base/error.h"
#include "pvrr/gl/context.h"

namespace fs = std::filesystem;

namespace pvrr::app {

namespace {

// vtkGenericOpenGLRenderWindow hosted in a context we made current; VTK 9.1's OpenGLInitContext minus the
// fatal check for a GLX display (Debian's GLEW is a GLX build; the entry points still load through GLVND).
class ExternalGLRenderWindow : public vtkGenericOpenGLRenderWindow {
 public:
  static ExternalGLRenderWindow* New();
  vtkTypeMacro(ExternalGLRenderWindow, vtkGenericOpenGLRenderWindow);

 protected:
  void OpenGLInitContext() override {
    this->ContextCreationTime.Modified();
    if (this->Initialized) return;
    const GLenum r = glewInit();
    if (r != GLEW_OK && r != GLEW_ERROR_NO_GLX_DISPLAY) return;
    if (!GLEW_VERSION_3_2) return;
    this->GlewInitValid = true;
    this->Initialized = true;
    GLfloat lw[2] = {1, 1};
    glGetFloatv(GL_ALIASED_LINE_WIDTH_RANGE, lw);
    this->MaximumHardwareLineWidth = lw[1];
  }
};
vtkStandardNewMacro(ExternalGLRenderWindow);

const unsigned char kColours[][3] = {{31, 119, 180}, {214, 39, 40}, {44, 160, 44}, {148, 103, 189}, {255, 127, 14}, {23, 190, 207}};
constexpr int kNumColours = 6;
const int kMarkers[] = {vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE, vtkPlotPoints::DIAMOND, vtkPlotPoints::CROSS,
                        vtkPlotPoints::PLUS};
constexpr int kNumMarkers = 5;

std::string seriesName(const SweepRow& r) {
  return r.mode + " map " + std::to_string(r.map_size) + (r.vary.empty() ? "" : " " + r.vary);
}

// Point labels drawn at the points themselves (vtkPlot's indexed labels are tooltips only). A label goes to
// the upper right of its point, or to the first of a few other spots that overlaps no label drawn before
// it in this chart (`placed`, in screen pixels, shared by the chart's labelled plots) and stays in the scene.
class LabelledPoints : public vtkPlotPoints {
 public:
  static LabelledPoints* New();
  vtkTypeMacro(LabelledPoints, vtkPlotPoints);
  std::vector<std::string> labels;
  std::vector<vtkRectf>* placed = nullptr;
  bool first = false;  // the chart's first labelled plot: a new paint of the chart starts, forget the old labels

  bool Paint(vtkContext2D* painter) override {
    if (!this->Superclass::Paint(painter)) return false;
    if (placed && first) placed->clear();
    if (!this->Points || labels.empty() || !this->Visible) return true;
    vtkTransform2D* to_screen = painter->GetTransform();
    const vtkIdType n = std::min<vtkIdType>(this->Points->GetNumberOfPoints(), vtkIdType(labels.size()));
    std::vector<float> data(size_t(2 * n)), screen(size_t(2 * n));
    for (vtkIdType i = 0; i < n; ++i) {
      double p[2];
      this->Points->GetPoint(i, p);
      data[size_t(2 * i)] = float(p[0]);
      data[size_t(2 * i + 1)] = float(p[1]);
    }
    to_screen->TransformPoints(data.data(), screen.data(), int(n));
    const vtkRecti scene_rect(0, 0, this->GetScene() ? this->GetScene()->GetSceneWidth() : 100000,
                              this->GetScene() ? this->GetScene()->GetSceneHeight() : 100000);
    painter->PushMatrix();
    vtkNew<vtkTransform2D> identity;
    painter->SetTransform(identity);
    vtkNew<vtkTextProperty> tp;
    tp->SetFontSize(11);
    tp->SetColor(0.15, 0.15, 0.15);
    tp->SetJustificationToLeft();
    tp->SetVerticalJustificationToBottom();
    painter->ApplyTextProp(tp);
    for (vtkIdType i = 0; i < n; ++i) {
      const std::string& text = labels[size_t(i)];
      const float sx = screen[size_t(2 * i)], sy = screen[size_t(2 * i + 1)];
      if (text.empty() || !std::isfinite(sx) || !std::isfinite(sy)) continue;
      float b[4];
      painter->ComputeStringBounds(text, b);
      const float w = b[2], h = b[3], gap = 5;
      // Upper right, lower right, upper left, lower left, then further up and down on the right.
      const float spots[][2] = {{gap, gap},          {gap, -gap - h},           {-gap - w, gap},
                                {-gap - w, -gap - h}, {gap, gap + 1.2f * h},     {gap, -gap - 2.2f * h},
                                {gap, gap + 2.4f * h}, {gap, -gap - 3.4f * h}};
      vtkRectf chosen(sx + spots[0][0], sy + spots[0][1], w, h);
      for (const auto& d : spots) {
        const vtkRectf r(sx + d[0], sy + d[1], w, h);
        const bool inside = r.GetX() >= 0 && r.GetY() >= 0 && r.GetX() + w <= float(scene_rect.GetWidth()) &&
                            r.GetY() + h <= float(scene_rect.GetHeight());
        bool overlaps = false;
        if (placed)
          for (const vtkRectf& o : *placed)
            overlaps = overlaps || (r.GetX() < o.GetX() + o.GetWidth() && o.GetX() < r.GetX() + w &&
                                    r.GetY() < o.GetY() + o.GetHeight() && o.GetY() < r.GetY() + h);
        if (inside && !overlaps) {
          chosen = r;
          break;
        }
      }
      if (placed) placed->push_back(chosen);
      painter->DrawString(chosen.GetX(), chosen.GetY(), text);
    }
    painter->PopMatrix();
    return true;
  }
};
vtkStandardNewMacro(LabelledPoints);

struct Axes {
  std::string title, xtitle, ytitle;
  bool log_x = false, log_y = false;
  std::pair<double, double> x_range, y_range;
};

// A chart of the series on fixed, padded axes with the legend outside the plot area, rendered into a PNG
// through our EGL context.
void renderChart(const std::string& path, const Axes& axes, const std::vector<PlotSeries>& series) {
  auto ctx = gl::GlContext::create(gl::GlBackend::Egl);
  vtkNew<ExternalGLRenderWindow> rw;
  rw->SetSize(1000, 640);
  rw->SetOffScreenRendering(1);
  rw->SetIsCurrent(true);
  rw->SetReadyForRendering(true);
  rw->SetOwnContext(false);
  rw->SetFrameBlitModeToNoBlit();
  gl::GlContext* raw = ctx.get();
  vtkNew<vtkCallbackCommand> make_current;
  make_current->SetClientData(raw);
  make_current->SetCallback([](vtkObject*, unsigned long, void* cd, void*) { static_cast<gl::GlContext*>(cd)->makeCurrent(); });
  vtkNew<vtkCallbackCommand> is_current;
  is_current->SetCallback([](vtkObject*, unsigned long, void*, void* call) { *static_cast<bool*>(call) = true; });
  vtkNew<vtkCallbackCommand> supports;
  supports->SetCallback([](vtkObject*, unsigned long, void*, void* call) { *static_cast<int*>(call) = 1; });
  rw->AddObserver(vtkCommand::WindowMakeCurrentEvent, make_current);
  rw->AddObserver(vtkCommand::WindowIsCurrentEvent, is_current);
  rw->AddObserver(vtkCommand::WindowSupportsOpenGLEvent, supports);
  rw->AddObserver(vtkCommand::WindowIsDirectEvent, supports);
  rw->InitializeFromCurrentContext();

  vtkNew<vtkContextView> view;
  view->SetRenderWindow(rw);
  view->GetRenderer()->SetBackground(1, 1, 1);
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  chart->SetTitle(axes.title);
  chart->SetShowLegend(true);
  // Outside the plot area, on the right: inside, it hides whatever lies in its corner.
  chart->GetLegend()->SetInline(false);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  chart->GetLegend()->SetDragEnabled(false);
  struct AxisSpec {
    int which;
    const std::string& title;
    bool log;
    std::pair<double, double> range;
  };
  for (const AxisSpec& a : {AxisSpec{vtkAxis::BOTTOM, axes.xtitle, axes.log_x, axes.x_range},
                            AxisSpec{vtkAxis::LEFT, axes.ytitle, axes.log_y, axes.y_range}}) {
    vtkAxis* ax = chart->GetAxis(a.which);
    ax->SetTitle(a.title);
    ax->SetLogScale(a.log);
    ax->SetBehavior(vtkAxis::FIXED);
    ax->SetUnscaledRange(a.range.first, a.range.second);
  }
  std::vector<vtkRectf> placed;
  bool any_labelled = false;
  std::vector<vtkSmartPointer<vtkTable>> tables;
  for (const PlotSeries& s : series) {
    auto table = vtkSmartPointer<vtkTable>::New();
    vtkNew<vtkDoubleArray> xs, ys;
    xs->SetName("x");
    ys->SetName(s.name.c_str());
    for (size_t i = 0; i < s.x.size(); ++i) {
      xs->InsertNextValue(s.x[i]);
      ys->InsertNextValue(s.y[i]);
    }
    table->AddColumn(xs);
    table->AddColumn(ys);
    vtkPlot* p = nullptr;
    // A line of one point draws nothing (and VTK logs an error): that point gets a marker instead.
    const bool as_line = s.line && s.x.size() >= 2;
    if (as_line) {
      p = chart->AddPlot(vtkChart::LINE);
    } else {
      vtkNew<LabelledPoints> lp;
      lp->labels = s.labels;
      lp->placed = &placed;
      lp->first = !any_labelled;
      any_labelled = true;
      lp->SetMarkerStyle(kMarkers[s.marker % kNumMarkers]);
      lp->SetMarkerSize(9);
      chart->AddPlot(lp);
      p = lp;
    }
    p->SetInputData(table, 0, 1);
    if (s.colour < 0) {
      p->SetColor(0, 0, 0, 255);
    } else {
      const unsigned char* c = kColours[s.colour % kNumColours];
      p->SetColor(c[0], c[1], c[2], 255);
    }
    p->SetWidth(as_line ? 2.0f : 3.0f);
    if (s.dashed) p->GetPen()->SetLineType(vtkPen::DASH_LINE);
    tables.push_back(table);
  }
  rw->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(rw);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  writeAtomic(path, [&](const std::string& temp) {
    vtkNew<vtkPNGWriter> w;
    w->SetFileName(temp.c_str());
    w->SetInputConnection(grab->GetOutputPort());
    w->Write();
    if (!fs::exists(temp)) throw Error(path + ": VTK could not write the plot");
  });
}

// An SVG marker of the chart's marker set at (x, y).
std::string svgMarker(double x, double y, int marker, const std::string& colour) {
  std::ostringstream s;
  const double r = 4.5;
  switch (marker % kNumMarkers) {
    case 0: s << "<circle cx='" << x << "' cy='" << y << "' r='" << r << "' fill='" << colour << "'/>"; break;
    case 1: s << "<rect x='" << x - r << "' y='" << y - r << "' width='" << 2 * r << "' height='" << 2 * r << "' fill='" << colour << "'/>"; break;
    case 2:
      s << "<polygon points='" << x << "," << y - r - 1 << " " << x + r + 1 << "," << y << " " << x << "," << y + r + 1 << " "
        << x - r - 1 << "," << y << "' fill='" << colour << "'/>";
      break;
    case 3:
      s << "<path d='M" << x - r << "," << y - r << "L" << x + r << "," << y + r << "M" << x - r << "," << y + r << "L" << x + r << ","
        << y - r << "' stroke='" << colour << "' stroke-width='2'/>";
      break;
    default:
      s << "<path d='M" << x - r << "," << y << "L" << x + r << "," << y << "M" << x << "," << y - r << "L" << x << "," << y + r
        << "' stroke='" << colour << "' stroke-width='2'/>";
  }
  return s.str();
}

std::string rgb(int colour) {
  const unsigned char* c = kColours[colour % kNumColours];
  return "rgb(" + std::to_string(int(c[0])) + "," + std::to_string(int(c[1])) + "," + std::to_string(int(c[2])) + ")";
}

// The same error-vs-time chart as SVG, every point labelled "N/S" (tessellation / map size).
std::string svgErrorVsTime(const std::vector<PlotSeries>& series, double reference_ms, std::pair<double, double> xr,
                           std::pair<double, double> yr) {
  const double W = 1000, H = 640, L = 90, R = 240, T = 50, B = 70;
  const double x0 = xr.first, x1 = xr.second, y0 = yr.first, y1 = yr.second;
  auto X = [&](double v) { return L + (v - x0) / (x1 - x0) * (W - L - R); };
  auto Y = [&](double v) { return H - B - (std::log10(std::max(v, y0)) - std::log10(y0)) / (std::log10(y1) - std::log10(y0)) * (H - T - B); };
  std::ostringstream s;
  s << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H << "' font-family='sans-serif' font-size='12'>\n";
  s << "<rect width='100%' height='100%' fill='white'/>\n";
  s << "<text x='" << W / 2 << "' y='25' text-anchor='middle' font-size='16'>Median angular error against frame time</text>\n";
  s << "<line x1='" << L << "' y1='" << H - B << "' x2='" << W - R << "' y2='" << H - B << "' stroke='black'/>\n";
  s << "<line x1='" << L << "' y1='" << T << "' x2='" << L << "' y2='" << H - B << "' stroke='black'/>\n";
  s << "<text x='" << (L + W - R) / 2 << "' y='" << H - 25 << "' text-anchor='middle'>frame time (ms)</text>\n";
  s << "<text transform='translate(25," << (T + H - B) / 2 << ") rotate(-90)' text-anchor='middle'>median angular error (arcmin, log)</text>\n";
  for (int d = int(std::floor(std::log10(y0))); d <= int(std::ceil(std::log10(y1))); ++d) {
    const double v = std::pow(10.0, d);
    if (v < y0 || v > y1) continue;
    s << "<line x1='" << L - 5 << "' y1='" << Y(v) << "' x2='" << W - R << "' y2='" << Y(v) << "' stroke='#ddd'/>";
    s << "<text x='" << L - 8 << "' y='" << Y(v) + 4 << "' text-anchor='end'>1e" << d << "</text>\n";
  }
  for (int i = 0; i <= 5; ++i) {
    const double v = x0 + (x1 - x0) * i / 5;
    s << "<text x='" << X(v) << "' y='" << H - B + 18 << "' text-anchor='middle'>" << std::round(v * 10) / 10 << "</text>\n";
  }
  s << "<line x1='" << X(reference_ms) << "' y1='" << T << "' x2='" << X(reference_ms) << "' y2='" << H - B
    << "' stroke='black' stroke-dasharray='6,4'/><text x='" << X(reference_ms) + 4 << "' y='" << T + 12 << "'>reference "
    << std::round(reference_ms * 10) / 10 << " ms</text>\n";
  int k = 0;
  for (const PlotSeries& ps : series) {
    if (ps.line) continue;
    const std::string c = rgb(ps.colour);
    for (size_t i = 0; i < ps.x.size(); ++i) {
      s << svgMarker(X(ps.x[i]), Y(ps.y[i]), ps.marker, c);
      if (i < ps.labels.size())
        s << "<text x='" << X(ps.x[i]) + 6 << "' y='" << Y(ps.y[i]) - 4 << "' font-size='10'>" << ps.labels[i] << "</text>";
      s << "\n";
    }
    s << svgMarker(W - R + 20, T + 20 * k, ps.marker, c) << "<text x='" << W - R + 30 << "' y='" << T + 4 + 20 * k << "'>" << ps.name
      << "</text>\n";
    ++k;
  }
  s << "<text x='" << W - R + 20 << "' y='" << T + 20 * k + 10 << "' font-size='10'>labels: tessellation/map size</text>\n";
  s << "</svg>\n";
  return s.str();
}

}  // namespace

std::string sweepCsv(const std::vector<SweepRow>& rows) {
  std::ostringstream s;
  s.precision(17);
  s << "mode,tessellation,map_size,vertices,frame_ms,median_arcmin,p95_arcmin,max_arcmin,psnr_db,reference_ms,vary\n";
  for (const SweepRow& r : rows)
    s << r.mode << ',' << r.tessellation << ',' << r.map_size << ',' << r.vertices << ',' << r.frame_ms << ',' << r.median_arcmin
      << ',' << r.p95_arcmin << ',' << r.max_arcmin << ',' << r.psnr_db << ',' << r.reference_ms << ',' << r.vary << '\n';
  return s.str();
}

std::vector<SweepRow> readSweepCsv(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw Error(path + ": cannot open");
  std::string line;
  if (!std::getline(in, line) || line.rfind("mode,tessellation,map_size,vertices,frame_ms,median_arcmin", 0) != 0)
    throw Error(path + ":1: expected the sweep header (mode,tessellation,map_size,vertices,frame_ms,median_arcmin,...)");
  std::vector<SweepRow> rows;
  for (int n = 2; std::getline(in, line); ++n) {
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) f.push_back(cell);
    if (f.size() < 10) throw Error(path + ":" + std::to_string(n) + ": expected at least 10 columns, got " + std::to_string(f.size()));
    try {
      SweepRow r;
      r.mode = f[0];
      r.tessellation = std::stoi(f[1]);
      r.map_size = std::stoi(f[2]);
      r.vertices = std::stol(f[3]);
      r.frame_ms = std::stod(f[4]);
      r.median_arcmin = std::stod(f[5]);
      r.p95_arcmin = std::stod(f[6]);
      r.max_arcmin = std::stod(f[7]);
      r.psnr_db = std::stod(f[8]);
      r.reference_ms = std::stod(f[9]);
      r.vary = f.size() > 10 ? f[10] : "";
      if (!std::isfinite(r.frame_ms) || !std::isfinite(r.median_arcmin)) throw std::invalid_argument("not finite");
      rows.push_back(r);
    } catch (const std::exception&) {
      throw Error(path + ":" + std::to_string(n) + ": expected numbers in columns 2-10, got \"" + line + "\"");
    }
  }
  if (rows.empty()) throw Error(path + ": no rows");
  return rows;
}

std::pair<double, double> paddedRange(const std::vector<double>& values, bool log) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (double v : values)
    if (std::isfinite(v) && (!log || v > 0)) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(lo <= hi)) throw Error(std::string("plot: no finite ") + (log ? "positive " : "") + "value to scale an axis to");
  if (log) return {lo / 1.6, hi * 1.6};
  const double pad = hi > lo ? 0.08 * (hi - lo) : std::max(0.1 * std::abs(lo), 1e-9);
  // Start at 0 rather than below it when the lowest value keeps a quarter of the padding (2 % of the span,
  // ~15 px on the chart) from the border.
  return {lo - pad < 0 && lo >= 0.25 * pad ? 0.0 : lo - pad, hi + pad};
}

std::vector<PlotSeries> errorVsTimeSeries(const std::vector<SweepRow>& rows) {
  std::vector<PlotSeries> out;
  std::map<std::string, size_t> index;  // series name -> position in `out`
  for (const SweepRow& r : rows) {
    const std::string name = seriesName(r);
    auto it = index.find(name);
    if (it == index.end()) {
      PlotSeries s;
      s.name = name;
      const int k = int(out.size());
      // Colours cycle first; the marker changes once per round of colours, so (colour, marker) stays unique
      // for kNumColours * kNumMarkers series.
      s.colour = k % kNumColours;
      s.marker = (k / kNumColours) % kNumMarkers;
      it = index.emplace(name, out.size()).first;
      out.push_back(s);
    }
    PlotSeries& s = out[it->second];
    s.x.push_back(r.frame_ms);
    s.y.push_back(std::max(r.median_arcmin, 1e-6));
    s.labels.push_back(std::to_string(r.tessellation) + "/" + std::to_string(r.map_size));
  }
  return out;
}

void writeSweepPlots(const std::string& dir, const std::vector<SweepRow>& rows) {
  if (rows.empty()) throw Error(dir + ": no sweep rows to plot");
  // Error against frame time: one labelled point series per (mode, map size, vary) group.
  std::vector<PlotSeries> time_series = errorVsTimeSeries(rows);
  std::vector<double> xs = {rows.front().reference_ms}, ys;
  for (const PlotSeries& s : time_series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  Axes ta;
  ta.title = "Median angular error against frame time (labels: tessellation/map size)";
  ta.xtitle = "frame time (ms)";
  ta.ytitle = "median angular error (arcmin)";
  ta.log_y = true;
  ta.x_range = paddedRange(xs, false);
  ta.y_range = paddedRange(ys, true);
  PlotSeries ref;
  ref.name = "reference frame time";
  ref.line = true;
  ref.colour = -1;  // black
  ref.x = {rows.front().reference_ms, rows.front().reference_ms};
  ref.y = {ta.y_range.first, ta.y_range.second};
  std::vector<PlotSeries> with_ref = time_series;
  with_ref.push_back(ref);
  renderChart(dir + "/error_vs_time.png", ta, with_ref);
  writeFileAtomic(dir + "/error_vs_time.svg", svgErrorVsTime(time_series, rows.front().reference_ms, ta.x_range, ta.y_range));

  // Median and p95 against vertex count, one pair of lines per mode (and vary), sorted by vertex count.
  std::map<std::string, PlotSeries> med, p95;
  std::vector<std::string> order;
  for (const SweepRow& r : rows) {
    const std::string key = r.mode + (r.vary.empty() ? "" : " " + r.vary) + " map " + std::to_string(r.map_size);
    if (!med.count(key)) {
      const int k = int(order.size());
      order.push_back(key);
      med[key].name = key + " median";
      p95[key].name = key + " p95";
      med[key].colour = p95[key].colour = k % kNumColours;
      med[key].line = p95[key].line = true;
      p95[key].dashed = true;
    }
    med[key].x.push_back(double(r.vertices));
    med[key].y.push_back(std::max(r.median_arcmin, 1e-6));
    p95[key].x.push_back(double(r.vertices));
    p95[key].y.push_back(std::max(r.p95_arcmin, 1e-6));
  }
  std::vector<PlotSeries> vert_series;
  std::vector<double> vx, vy;
  for (const std::string& key : order)
    for (PlotSeries* ser : {&med[key], &p95[key]}) {
      std::vector<size_t> idx(ser->x.size());
      for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
      std::stable_sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return ser->x[a] < ser->x[b]; });
      PlotSeries sorted = *ser;
      for (size_t i = 0; i < idx.size(); ++i) {
        sorted.x[i] = ser->x[idx[i]];
        sorted.y[i] = ser->y[idx[i]];
      }
      vx.insert(vx.end(), sorted.x.begin(), sorted.x.end());
      vy.insert(vy.end(), sorted.y.begin(), sorted.y.end());
      vert_series.push_back(sorted);
    }
  Axes va;
  va.title = "Angular error against vertex count (lines: median and p95 per mode and map size)";
  va.xtitle = "vertices (log)";
  va.ytitle = "angular error (arcmin, log)";
  va.log_x = va.log_y = true;
  va.x_range = paddedRange(vx, true);
  va.y_range = paddedRange(vy, true);
  renderChart(dir + "/error_vs_vertices.png", va, vert_series);
}

}  // namespace pvrr::app
