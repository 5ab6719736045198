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
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <unistd.h>

#include "app/commands.h"
#include "cad/error.h"
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

std::string seriesName(const SweepRow& r) {
  return r.mode + " map " + std::to_string(r.map_size) + (r.vary.empty() ? "" : " " + r.vary);
}

// A chart from (x, y) series; log axes as asked. Rendered into a PNG through our EGL context.
struct Series {
  std::string name;
  std::vector<double> x, y;
  bool line = false;
  int colour = 0;
};

void renderChart(const std::string& path, const std::string& title, const std::string& xtitle, const std::string& ytitle,
                 bool log_x, bool log_y, const std::vector<Series>& series) {
  auto ctx = gl::GlContext::create(gl::GlBackend::Egl);
  vtkNew<ExternalGLRenderWindow> rw;
  rw->SetSize(900, 600);
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
  chart->SetTitle(title);
  chart->SetShowLegend(true);
  chart->GetAxis(vtkAxis::BOTTOM)->SetTitle(xtitle);
  chart->GetAxis(vtkAxis::LEFT)->SetTitle(ytitle);
  chart->GetAxis(vtkAxis::BOTTOM)->SetLogScale(log_x);
  chart->GetAxis(vtkAxis::LEFT)->SetLogScale(log_y);
  std::vector<vtkSmartPointer<vtkTable>> tables;
  for (const Series& s : series) {
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
    vtkPlot* p = chart->AddPlot(s.line ? vtkChart::LINE : vtkChart::POINTS);
    p->SetInputData(table, 0, 1);
    const unsigned char* c = kColours[s.colour % 6];
    p->SetColor(c[0], c[1], c[2], 255);
    p->SetWidth(s.line ? 2.0f : 4.0f);
    tables.push_back(table);
  }
  rw->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(rw);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();
  const std::string tmp = path + ".tmp-" + std::to_string(::getpid());
  vtkNew<vtkPNGWriter> w;
  w->SetFileName(tmp.c_str());
  w->SetInputConnection(grab->GetOutputPort());
  w->Write();
  std::error_code ec;
  if (!fs::exists(tmp)) throw Error(path + ": VTK could not write the plot");
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw Error(path + ": cannot rename the temporary file into place");
  }
}

// The same error-vs-time chart as SVG, every point labelled "N/S" (tessellation / map size).
std::string svgErrorVsTime(const std::vector<SweepRow>& rows) {
  const double W = 900, H = 600, L = 90, R = 220, T = 50, B = 70;
  double x0 = 1e300, x1 = 0, y0 = 1e300, y1 = 0;
  for (const SweepRow& r : rows) {
    x0 = std::min({x0, r.frame_ms, r.reference_ms});
    x1 = std::max({x1, r.frame_ms, r.reference_ms});
    if (r.median_arcmin > 0) {
      y0 = std::min(y0, r.median_arcmin);
      y1 = std::max(y1, r.median_arcmin);
    }
  }
  x0 *= 0.8, x1 *= 1.25, y0 = std::max(y0 * 0.5, 1e-6), y1 *= 2;
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
  const double ref = rows.empty() ? 0 : rows.front().reference_ms;
  s << "<line x1='" << X(ref) << "' y1='" << T << "' x2='" << X(ref) << "' y2='" << H - B
    << "' stroke='black' stroke-dasharray='6,4'/><text x='" << X(ref) + 4 << "' y='" << T + 12 << "'>reference " << std::round(ref * 10) / 10 << " ms</text>\n";
  std::map<std::string, int> colour;
  for (const SweepRow& r : rows) colour.emplace(seriesName(r), int(colour.size()));
  for (const SweepRow& r : rows) {
    const unsigned char* c = kColours[colour[seriesName(r)] % 6];
    s << "<circle cx='" << X(r.frame_ms) << "' cy='" << Y(r.median_arcmin) << "' r='4' fill='rgb(" << int(c[0]) << ","
      << int(c[1]) << "," << int(c[2]) << ")'/><text x='" << X(r.frame_ms) + 6 << "' y='" << Y(r.median_arcmin) - 4
      << "' font-size='10'>" << r.tessellation << "/" << r.map_size << "</text>\n";
  }
  int k = 0;
  for (const auto& [name, idx] : colour) {
    const unsigned char* c = kColours[idx % 6];
    s << "<circle cx='" << W - R + 20 << "' cy='" << T + 20 * k << "' r='4' fill='rgb(" << int(c[0]) << "," << int(c[1]) << ","
      << int(c[2]) << ")'/><text x='" << W - R + 30 << "' y='" << T + 4 + 20 * k << "'>" << name << "</text>\n";
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

void writeSweepPlots(const std::string& dir, const std::vector<SweepRow>& rows) {
  std::map<std::string, int> colour;
  std::map<std::string, Series> by_series, med, p95;
  for (const SweepRow& r : rows) {
    const std::string name = seriesName(r);
    const int c = colour.emplace(name, int(colour.size())).first->second;
    Series& s = by_series[name];
    s.name = name;
    s.colour = c;
    s.x.push_back(r.frame_ms);
    s.y.push_back(std::max(r.median_arcmin, 1e-6));
    Series& m = med[r.mode];
    m.name = r.mode + " median";
    m.colour = 2 * int(med.size() - 1);
    m.x.push_back(double(r.vertices));
    m.y.push_back(std::max(r.median_arcmin, 1e-6));
    Series& p = p95[r.mode];
    p.name = r.mode + " p95";
    p.colour = 2 * int(p95.size() - 1) + 1;
    p.x.push_back(double(r.vertices));
    p.y.push_back(std::max(r.p95_arcmin, 1e-6));
  }
  std::vector<Series> time_series;
  double lo = 1e300, hi = 0;
  for (auto& [name, s] : by_series) {
    time_series.push_back(s);
    for (double y : s.y) lo = std::min(lo, y), hi = std::max(hi, y);
  }
  Series ref;
  ref.name = "reference frame time";
  ref.line = true;
  ref.colour = 5;
  ref.x = {rows.front().reference_ms, rows.front().reference_ms};
  ref.y = {lo, hi};
  time_series.push_back(ref);
  renderChart(dir + "/error_vs_time.png", "Median angular error against frame time (points: tessellation x map size)",
              "frame time (ms)", "median angular error (arcmin)", false, true, time_series);
  writeFileAtomic(dir + "/error_vs_time.svg", svgErrorVsTime(rows));
  std::vector<Series> vert_series;
  for (auto& [mode, s] : med) {
    // Sort by vertex count so the lines run left to right.
    std::vector<size_t> idx(s.x.size());
    for (size_t i = 0; i < idx.size(); ++i) idx[i] = i;
    std::sort(idx.begin(), idx.end(), [&](size_t a, size_t b) { return s.x[a] < s.x[b]; });
    for (Series* ser : {&s, &p95[mode]}) {
      Series sorted = *ser;
      for (size_t i = 0; i < idx.size(); ++i) {
        sorted.x[i] = ser->x[idx[i]];
        sorted.y[i] = ser->y[idx[i]];
      }
      sorted.line = true;
      vert_series.push_back(sorted);
    }
  }
  renderChart(dir + "/error_vs_vertices.png", "Angular error against vertex count", "vertices (log)",
              "angular error (arcmin, log)", true, true, vert_series);
}

}  // namespace pvrr::app
