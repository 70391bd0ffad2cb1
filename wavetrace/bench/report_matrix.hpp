// `wavetrace bench report`: the stated matrix of benchmark runs behind the report's charts
// and tables, each a wavetrace command line, so that the report can print what made it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace wavetrace {

struct ReportRun {
  std::string name;     // the JSON it writes is data/NAME.json
  std::string section;  // pareto, footprint, hmq_error, hmq_image, faults, stages, stability, leaks, world
  std::vector<std::string> arguments;  // after the wavetrace binary
};

struct ReportMatrixOptions {
  bool quick = false;        // small scenes and counts: every chart and row, in seconds (the test's)
  std::string data_dir;      // where each run's JSON goes
  std::string mesh_path;     // the real mesh (data/bunny00.off)
  // Triangles of each scene, for auto's budgets per triangle (room, sphere, the mesh).
  std::size_t room_triangles = 0, sphere_triangles = 0, mesh_triangles = 0;
};

// Scenes of the matrix as the runs name them.
struct ReportScenes {
  std::string room, sphere, soup, stadium, fur;
  std::vector<std::string> mesh;  // the real mesh's --scene and --set arguments
};
ReportScenes report_scenes(const ReportMatrixOptions& options);

std::vector<ReportRun> report_matrix(const ReportMatrixOptions& options);

// A command line as a shell would take it back (arguments quoted where they need it).
std::string shell_command(const std::string& program, const std::vector<std::string>& arguments);

}  // namespace wavetrace
