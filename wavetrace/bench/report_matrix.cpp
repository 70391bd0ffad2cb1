// The report's runs: which scenes, accelerators, ray kinds and budgets, in one place.
#include "wavetrace/bench/report_matrix.hpp"

#include <algorithm>
#include <string_view>

#include <fmt/format.h>

#include "wavetrace/setup/accel_choice.hpp"

namespace wavetrace {
namespace {

std::vector<std::string> join(std::vector<std::string> first, const std::vector<std::string>& second) {
  first.insert(first.end(), second.begin(), second.end());
  return first;
}

// auto under budgets that leave out the uncompressed structures: besides the process, 85
// bytes a triangle (HMQ fits, at the pixel bound) and `exact_bytes` with max_error = 0 (90:
// Ray-Strips and mlgrid fit), with chunks of an eighth of the scene, so that the build's
// temporaries are what they are at scale. Robust Embree's renders need 97 (sphere) to 130 (the
// bunny) bytes a triangle above that process allowance: at 100, the sphere's fitted by 3 MB,
// inside any estimate's margin, and the budget left out nothing it was meant to.
std::size_t tight_chunk(std::size_t triangles) { return std::max<std::size_t>(2048, triangles / 8); }

// The report's accel runs render at 320x240 (for pixel bounds): auto counts the process so.
std::size_t report_process_bytes() { return auto_allowance(ImageSpec{320, 240}).process_bytes; }

std::string tight_auto_specs(std::size_t triangles, std::size_t lossy_bytes = 85, std::size_t exact_bytes = 90) {
  const std::size_t chunk = tight_chunk(triangles);
  const std::size_t process = report_process_bytes();
  return fmt::format("auto:memory_budget={}:chunk_triangles={},auto:memory_budget={}:max_error=0:chunk_triangles={}",
                     process + lossy_bytes * triangles, chunk, process + exact_bytes * triangles, chunk);
}

// The compact candidates built in the tight autos' chunks: what auto's choice is measured
// against at those budgets (a whole build's temporaries would not fit them).
std::string chunked_settings(std::size_t triangles) {
  const std::size_t chunk = tight_chunk(triangles);
  return fmt::format("hmq:width=8:chunk_triangles={0},raystrips:width=8:chunk_triangles={0},bvh:width=8:chunk_triangles={0}",
                     chunk);
}

}  // namespace

ReportScenes report_scenes(const ReportMatrixOptions& options) {
  const std::string size = options.quick ? "20k" : "1M";
  ReportScenes scenes{"builtin:room:" + size,    "builtin:sphere:" + size, "builtin:soup:" + size,
                      "builtin:stadium:" + size, "builtin:fur:" + size,    {options.mesh_path}};
  if (!options.quick) scenes.mesh = {options.mesh_path, "--set", "scene.subdivide=2"};
  return scenes;
}

std::vector<ReportRun> report_matrix(const ReportMatrixOptions& options) {
  const ReportScenes scenes = report_scenes(options);
  const bool quick = options.quick;
  const std::string data = options.data_dir;
  const auto json = [&](const std::string& name) { return data + "/" + name + ".json"; };
  const std::string rays = quick ? "4000" : "300000";
  const std::string repeat = quick ? "1" : "3";
  const std::string image_size = quick ? "64x48" : "320x240";
  const std::string image_spp = quick ? "1" : "4";
  // Faults: one image for the simulated and the real pager alike, small because every real
  // fault is a read from disk (64x48 at 50%: 22k reads of 1 MiB, 29 s, with heuristic none).
  const std::string fault_size = quick ? "24x18" : "64x48";
  // The proxy runs (fur against room) are cheap: a larger image.
  const std::string proxy_size = quick ? "48x36" : "160x120";
  const std::string page_bytes = quick ? "memory.page_bytes=65536" : "memory.page_bytes=1048576";
  // A pixel bound means a pixel of the report's images.
  const std::vector<std::string> image_pixels = {"--set", "render.width=" + image_size.substr(0, image_size.find('x')),
                                                 "--set", "render.height=" + image_size.substr(image_size.find('x') + 1)};
  const std::vector<std::string> accel_common =
      join({"--count", rays, "--repeat", repeat, "--threads", "2", "--reference", "embree:mode=robust"}, image_pixels);
  const std::string every_setting =
      "embree,embree:mode=compact,embree:mode=robust,bvh,bvh:width=8,raystrips,raystrips:width=8,hmq,hmq:width=8,grid,"
      "mlgrid,auto";

  std::vector<ReportRun> runs;
  const std::vector<std::pair<std::string, std::vector<std::string>>> pareto_scenes = {
      {"room", {scenes.room}}, {"sphere", {scenes.sphere}}, {"mesh", scenes.mesh}};
  const std::size_t counts[] = {options.room_triangles, options.sphere_triangles, options.mesh_triangles};
  for (std::size_t s = 0; s < pareto_scenes.size(); ++s) {
    const auto& [label, scene] = pareto_scenes[s];
    for (const std::string kind : {"primary", "diffuse"}) {
      const std::string name = "pareto_" + label + "_" + kind;
      runs.push_back({name, "pareto",
                      join(join({"bench", "accel", "--scene"}, scene),
                           join({"--accel", every_setting + "," + chunked_settings(counts[s]) + "," + tight_auto_specs(counts[s]),
                                 "--rays", kind, "--json",
                                 json(name)},
                                accel_common))});
    }
  }

  // Each setting's footprint as the OS measures it (VmHWM) in a render of its own, at the
  // accel runs' image size: what auto's budget bounds, and what "fits" means in the report.
  // Default and compact Embree are left out: they leak, so they never count as fitting.
  constexpr std::string_view kLeakySettings[] = {"embree", "embree:mode=compact"};
  for (std::size_t s = 0; s < pareto_scenes.size(); ++s) {
    const auto& [label, scene] = pareto_scenes[s];
    const std::string settings = every_setting + "," + chunked_settings(counts[s]) + "," + tight_auto_specs(counts[s]);
    std::size_t k = 0;
    for (std::size_t begin = 0; begin <= settings.size();) {
      const std::size_t end = std::min(settings.find(',', begin), settings.size());
      const std::string spec = settings.substr(begin, end - begin);
      begin = end + 1;
      if (std::find(std::begin(kLeakySettings), std::end(kLeakySettings), spec) != std::end(kLeakySettings)) continue;
      const std::string name = fmt::format("footprint_{}_{}", label, k++);
      runs.push_back({name, "footprint",
                      join(join({"render"}, scene),
                           {"--accel", spec, "--size", image_size, "--spp", "1", "--threads", "2", "--out",
                            data + "/" + name + ".exr", "--stats", json(name)})});
    }
  }

  runs.push_back({"hmq_error", "hmq_error",
                  join({"bench", "accel", "--scene", scenes.room, "--rays", "primary", "--accel",
                        "embree:mode=robust,hmq:width=8:bits=6,hmq:width=8:bits=8,hmq:width=8:bits=10,hmq:width=8:bits=12,"
                        "hmq:width=8:bits=14,hmq:width=8:bits=16,hmq:width=8:epsilon=pixel",
                        "--json", json("hmq_error")},
                       accel_common)});
  runs.push_back({"hmq_image", "hmq_image",
                  {"bench", "image", "--scene", scenes.room, "--accel",
                   "embree:mode=robust,hmq:width=8:bits=8,hmq:width=8:bits=10,hmq:width=8:bits=12,hmq:width=8:bits=16,"
                   "hmq:width=8:epsilon=pixel",
                   "--noise", "--size", image_size, "--spp", image_spp, "--threads", "2", "--json", json("hmq_image")}});

  const std::string heuristics = "none,origin,origin_dir,hph,hph_dir";
  for (const std::string budget : {"50%", "30%", "10%"}) {
    const std::string name = "faults_simulated_" + budget.substr(0, budget.size() - 1);
    runs.push_back({name, "faults",
                    {"bench", "reorder", "--scene", scenes.room, "--accel", "bvh", "--heuristics", heuristics, "--size",
                     fault_size, "--spp", "1", "--threads", "1", "--set", "memory.budget=" + budget, "--set", page_bytes,
                     "--json", json(name)}});
  }
  const std::string world = data + "/room_bvh.wtw";
  runs.push_back({"world_room", "world",
                  {"build", scenes.room, "--accel", "bvh", "--proxy", "--out", world, "--stats", json("world_room")}});
  // Real reads cost about a millisecond each: fewer heuristics and budgets.
  const std::vector<std::string> real_budgets = quick ? std::vector<std::string>{"50%"} : std::vector<std::string>{"50%", "30%"};
  for (const std::string& budget : real_budgets) {
    const std::string name = "faults_real_" + budget.substr(0, budget.size() - 1);
    runs.push_back({name, "faults",
                    {"bench", "reorder", "--scene", world, "--heuristics", "none,origin,hph", "--size", fault_size,
                     "--spp", "1", "--threads", "1", "--set",
                     "memory.backing=file", "--set", "memory.budget=" + budget, "--set", page_bytes, "--json",
                     json(name)}});
  }

  for (const std::string heuristic : {"none", "hph"}) {
    const std::string name = "stages_" + heuristic;
    runs.push_back({name, "stages",
                    {"render", scenes.room, "--size", image_size, "--spp", image_spp, "--threads", "2", "--set",
                     "reorder.heuristic=" + heuristic, "--out", data + "/" + name + ".exr", "--stats", json(name)}});
  }

  const std::size_t triangles = options.sphere_triangles;
  runs.push_back({"stability_soup", "stability",
                  join({"bench", "accel", "--scene", scenes.soup, "--rays", "primary", "--accel",
                        // A soup's mesh is 52 bytes a triangle (three vertices each), not 22.
                        "embree:mode=robust,raystrips:width=8,grid,auto," + tight_auto_specs(triangles, 110, 140), "--json",
                        json("stability_soup")},
                       accel_common)});
  // Few rays: on builtin:stadium:1M a grid ray entering the sphere's cells tests most of its
  // million triangles (about 0.1 s a ray).
  runs.push_back({"stability_stadium", "stability",
                  join({"bench", "accel", "--scene", scenes.stadium, "--rays", "primary", "--accel",
                        "embree:mode=robust,grid,hmq:width=8,auto," + tight_auto_specs(triangles), "--json",
                        json("stability_stadium"), "--count", quick ? "500" : "2000", "--repeat", "1", "--threads", "2",
                        "--reference", "embree:mode=robust"},
                       image_pixels)});
  runs.push_back({"stability_fur_hmq", "stability",
                  join({"bench", "accel", "--scene", scenes.fur, "--rays", "primary", "--accel",
                        "embree:mode=robust,hmq:width=8:bits=10,hmq:width=8,auto", "--json", json("stability_fur_hmq")},
                       accel_common)});
  runs.push_back({"stability_fur_proxy", "stability",
                  {"bench", "reorder", "--scene", scenes.fur, "--accel", "embree", "--heuristics", "none,hph", "--size",
                   proxy_size, "--spp", "2", "--threads", "2", "--json", json("stability_fur_proxy")}});
  runs.push_back({"stability_room_proxy", "stability",
                  {"bench", "reorder", "--scene", scenes.room, "--accel", "embree", "--heuristics", "none,hph", "--size",
                   proxy_size, "--spp", "2", "--threads", "2", "--json", json("stability_room_proxy")}});
  runs.push_back({"leaks", "leaks",
                  {"bench", "leak", "--scene", scenes.sphere, "--accel",
                   "embree,embree:mode=robust,hmq:width=8,raystrips:width=8", "--count", quick ? "20000" : "4000000",
                   "--threads", "2", "--json", json("leaks")}});
  return runs;
}

std::string shell_command(const std::string& program, const std::vector<std::string>& arguments) {
  std::string command = program;
  for (const std::string& argument : arguments) {
    const bool plain = std::all_of(argument.begin(), argument.end(), [](char c) {
      return std::isalnum(static_cast<unsigned char>(c)) || std::string_view("-_./:=,%+").find(c) != std::string_view::npos;
    });
    command += " " + (plain && !argument.empty() ? argument : "'" + argument + "'");
  }
  return command;
}

}  // namespace wavetrace
