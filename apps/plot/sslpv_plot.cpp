// sslpv-plot IN.json OUT.png [--size WxH]: draws the table of `sslpv bench-error` (its
// PREFIX.json) as mean relative error against run time, both axes logarithmic, one
// colour and marker per scene, each scene's Pareto front joined by a line with larger
// markers. A separate program so that the sslpv binary never links VTK; Debian's VTK
// renders through X only, so it needs a display (bench-error starts it under xvfb-run
// when DISPLAY is unset). Exit codes as sslpv: 2 bad input, 3 no display or unwritable
// output, 1 internal error. The PNG is written to a temporary sibling and renamed.
#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextScene.h>
#include <vtkContextView.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPlotLine.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>
#include <unistd.h>
#include <utility>
#include <vector>

namespace {

namespace fs = std::filesystem;

struct Failure : std::runtime_error {
  Failure(int c, const std::string& message) : std::runtime_error(message), code(c) {}
  int code;
};

struct Point {
  double ms = 0, error = 0;
  bool pareto = false;
};

struct Series {
  std::string name;
  std::vector<Point> points;
};

struct Input {
  std::vector<Series> scenes;
  std::string subtitle;
  std::size_t dropped = 0;  ///< rows without a positive time and error (log axes)
};

Input readInput(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw Failure(2, file.string() + ": cannot read");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception& e) {
    throw Failure(2, file.string() + ": not JSON: " + e.what());
  }
  Input input;
  try {
    for (const nlohmann::json& row : j.at("rows")) {
      const std::string scene = fs::path(row.at("scene").get<std::string>()).stem().string();
      const nlohmann::json& ms = row.at("total_ms");
      const nlohmann::json& error = row.at("mean_relative_error");
      if (!ms.is_number() || !error.is_number() || !(ms.get<double>() > 0) || !(error.get<double>() > 0)) {
        ++input.dropped;
        continue;
      }
      auto it = std::find_if(input.scenes.begin(), input.scenes.end(),
                             [&](const Series& s) { return s.name == scene; });
      if (it == input.scenes.end()) it = input.scenes.insert(input.scenes.end(), Series{scene, {}});
      it->points.push_back({ms.get<double>(), error.get<double>(), row.at("pareto").get<bool>()});
    }
    input.subtitle = "reference " + std::to_string(j.at("spp").get<int>()) + " spp, metrics on " +
                     std::to_string(j.at("block").get<int>()) + "x" + std::to_string(j.at("block").get<int>()) +
                     " blocks, time: median of " + std::to_string(j.at("repeats").get<int>()) + " timed renders";
  } catch (const nlohmann::json::exception& e) {
    throw Failure(2, file.string() + ": not a bench-error table: " + e.what());
  }
  if (input.scenes.empty()) throw Failure(2, file.string() + ": no row with a positive time and error to plot");
  return input;
}

vtkSmartPointer<vtkTable> makeTable(const std::vector<Point>& points) {
  vtkNew<vtkDoubleArray> x, y;
  x->SetName("total ms");
  y->SetName("mean relative error");
  auto table = vtkSmartPointer<vtkTable>::New();
  table->AddColumn(x);
  table->AddColumn(y);
  table->SetNumberOfRows(vtkIdType(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) {
    table->SetValue(vtkIdType(i), 0, points[i].ms);
    table->SetValue(vtkIdType(i), 1, points[i].error);
  }
  return table;
}

void plot(const Input& input, const fs::path& output, int width, int height) {
  // Tableau 10: distinguishable, and still apart in grey scale by the markers.
  static const unsigned char colors[][3] = {{31, 119, 180}, {255, 127, 14}, {44, 160, 44},  {214, 39, 40},
                                            {148, 103, 189}, {140, 86, 75}, {227, 119, 194}, {127, 127, 127},
                                            {188, 189, 34},  {23, 190, 207}};
  static const int markers[] = {vtkPlotPoints::CIRCLE, vtkPlotPoints::SQUARE, vtkPlotPoints::DIAMOND,
                                vtkPlotPoints::CROSS, vtkPlotPoints::PLUS};
  vtkNew<vtkContextView> view;
  view->GetRenderer()->SetBackground(1.0, 1.0, 1.0);
  vtkRenderWindow* window = view->GetRenderWindow();
  window->SetOffScreenRendering(1);
  window->SetSize(width, height);
  vtkNew<vtkChartXY> chart;
  view->GetScene()->AddItem(chart);
  chart->SetTitle("sslpv bench-error: error against run time (" + input.subtitle + ")");
  chart->GetTitleProperties()->SetFontSize(14);
  chart->SetShowLegend(true);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::RIGHT);
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  vtkAxis* x = chart->GetAxis(vtkAxis::BOTTOM);
  x->SetTitle("run time of a full frame, ms (wall clock, log scale)");
  x->SetLogScale(true);
  vtkAxis* y = chart->GetAxis(vtkAxis::LEFT);
  y->SetTitle("mean relative error against the reference (log scale)");
  y->SetLogScale(true);
  // Auto-ranging puts the extreme points on the frame, where half of each marker is cut.
  double range[4] = {HUGE_VAL, 0, HUGE_VAL, 0};
  for (const Series& series : input.scenes)
    for (const Point& p : series.points) {
      range[0] = std::min(range[0], p.ms);
      range[1] = std::max(range[1], p.ms);
      range[2] = std::min(range[2], p.error);
      range[3] = std::max(range[3], p.error);
    }
  for (int axis = 0; axis < 2; ++axis) {
    const double lo = range[2 * axis], hi = range[2 * axis + 1];
    const double pad = hi > lo ? std::pow(hi / lo, 0.06) : 1.5;  // 6 % of the decades shown
    vtkAxis* a = axis == 0 ? x : y;
    a->SetBehavior(vtkAxis::FIXED);
    a->SetUnscaledRange(lo / pad, hi * pad);
  }

  std::vector<vtkSmartPointer<vtkTable>> keep;
  for (std::size_t s = 0; s < input.scenes.size(); ++s) {
    const Series& series = input.scenes[s];
    const unsigned char* c = colors[s % std::size(colors)];
    const int marker = markers[s % std::size(markers)];
    keep.push_back(makeTable(series.points));
    auto* all = vtkPlotPoints::SafeDownCast(chart->AddPlot(vtkChart::POINTS));
    all->SetInputData(keep.back(), 0, 1);
    all->SetColor(c[0], c[1], c[2], 255);
    all->SetMarkerStyle(marker);
    all->SetMarkerSize(9);
    all->SetLabel(series.name);

    std::vector<Point> front;
    for (const Point& p : series.points)
      if (p.pareto) front.push_back(p);
    std::sort(front.begin(), front.end(), [](const Point& a, const Point& b) { return a.ms < b.ms; });
    if (front.empty()) continue;
    keep.push_back(makeTable(front));
    auto* line = vtkPlotLine::SafeDownCast(chart->AddPlot(vtkChart::LINE));
    line->SetInputData(keep.back(), 0, 1);
    line->SetColor(c[0], c[1], c[2], 255);
    line->SetWidth(2.0f);
    line->SetMarkerStyle(marker);
    line->SetMarkerSize(16);
    line->SetLabel(series.name + ": Pareto front");
  }

  window->Render();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();

  fs::path temp = output;
  temp += ".tmp-" + std::to_string(::getpid());
  vtkNew<vtkPNGWriter> writer;
  writer->SetFileName(temp.c_str());
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  std::error_code ec;
  if (writer->GetErrorCode() != 0 || !fs::exists(temp)) {
    fs::remove(temp, ec);
    throw Failure(3, output.string() + ": cannot write the PNG");
  }
  fs::rename(temp, output, ec);
  if (ec) {
    fs::remove(temp, ec);
    throw Failure(3, output.string() + ": cannot replace file: " + ec.message());
  }
}

}  // namespace

int main(int argc, char** argv) {
  try {
    std::vector<std::string> args(argv + 1, argv + argc);
    int width = 1200, height = 800;
    if (args.size() == 4 && args[2] == "--size") {
      if (std::sscanf(args[3].c_str(), "%dx%d", &width, &height) != 2 || width < 200 || height < 150 ||
          width > 8192 || height > 8192)
        throw Failure(2, "--size: expected WxH between 200x150 and 8192x8192, got '" + args[3] + "'");
      args.resize(2);
    }
    if (args.size() != 2) throw Failure(2, "usage: sslpv-plot IN.json OUT.png [--size WxH]");
    const fs::path output = args[1];
    const fs::path dir = output.parent_path().empty() ? fs::path(".") : output.parent_path();
    if (!fs::is_directory(dir)) throw Failure(2, output.string() + ": directory '" + dir.string() + "' does not exist");
    const Input input = readInput(args[0]);
    const char* display = std::getenv("DISPLAY");
    if (!display || !*display)
      throw Failure(3, "DISPLAY is unset: VTK here renders through X only (run under xvfb-run -a)");
    if (input.dropped)
      std::cerr << "sslpv-plot: " << input.dropped << " rows without a positive time and error are not shown\n";
    plot(input, output, width, height);
    return 0;
  } catch (const Failure& e) {
    std::cerr << "sslpv-plot: error: " << e.what() << std::endl;
    return e.code;
  } catch (const std::exception& e) {
    std::cerr << "sslpv-plot: error: internal error: " << e.what() << std::endl;
    return 1;
  }
}
