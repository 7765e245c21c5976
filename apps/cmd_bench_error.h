#pragma once
// `sslpv bench-error SCENES... -o PREFIX`: run time against error. Renders every
// configuration (cross product of the comma lists) of every scene, compares each with a
// cached path-traced reference (volume/eval/image_metrics.h) and writes PREFIX.csv,
// PREFIX.json and PREFIX.png (error against time, Pareto fronts marked; drawn by the
// separate sslpv-plot program so the sslpv binary never links VTK).
#include <CLI/CLI.hpp>
#include <cstdint>
#include <string>
#include <vector>

namespace sslpv {

struct BenchErrorArgs {
  std::vector<std::string> scenes;
  std::string grid = "32,64";
  std::string steps = "8,auto";
  std::string shadowMap = "256";
  std::string backend = "cpu,vulkan";
  std::string scheme = "seed,calibrated";
  int spp = 256;               ///< reference samples per pixel
  std::uint64_t seed = 0;      ///< reference seed
  int block = 4;               ///< metrics on K×K block means (reference noise)
  int repeats = 3;             ///< timed renders per configuration, after one warm-up
  std::string cache = "sslpv-reference-cache";
  std::string output;          ///< prefix of the .csv, .json and .png
};

CLI::App* addBenchErrorCommand(CLI::App& app, BenchErrorArgs& args);

/// InputError (exit 2) on bad input before any work; ResourceError (exit 3) when the plot
/// could not be made (the CSV and JSON are written all the same) or nothing could run.
int runBenchError(const BenchErrorArgs& args);

}  // namespace sslpv
