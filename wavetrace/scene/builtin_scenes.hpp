// Procedural scenes named builtin:NAME[:TRIANGLES]; deterministic and generated in parallel.
//   sphere   a closed, fractally displaced icosphere (20 triangles and up)
//   ball     a smooth icosphere of radius 1 at the origin, facing out (glass in scene files)
//   plane    a flat square of side 2 centred on the origin in the xz plane, facing +y
//   terrain  a fractal heightfield
//   soup     the sphere's triangles with no shared vertices (no connectivity at all)
//   stadium  a small dense sphere inside a huge, sparse box (the grids' failure case)
//   fur      many thin disconnected strands on a small sphere (the proxy's failure case)
//   default  a displaced sphere on a ground plane under an area light, framed by the camera
//   room     a closed room lit from its ceiling holding displaced spheres, a terrain patch
//            and fur; the camera inside (the benchmark scene for bounces and reordering)
//   furnace  a closed sphere facing inward whose walls all emit kFurnaceEmission and reflect
//            kFurnaceAlbedo, the camera at its centre: radiance emission / (1 - albedo) = 2
#pragma once

#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

inline constexpr float kFurnaceEmission = 1.0f;
inline constexpr float kFurnaceAlbedo = 0.5f;

bool is_builtin_scene(std::string_view source);
std::vector<std::string> builtin_scene_names();

// Parses "builtin:NAME[:COUNT]" (COUNT with an optional k, M or G suffix) and builds it.
// The triangle count is met as closely as the generator's structure allows. Streamed, the
// scene keeps its generators (Scene::stream) and no mesh.
Scene make_builtin_scene(std::string_view source, bool streamed = false);

// The triangle count a builtin source asks for ("builtin:room:8M" -> 8000000), none when it
// names no count; throws SceneError for a malformed count.
std::optional<std::size_t> requested_triangle_count(std::string_view source);

// About the triangles make_builtin_scene makes for `source` (the requested count, or the
// builtin's default, raised to what its structure needs), known before anything is built;
// none for an unknown builtin. Throws SceneError for a malformed count.
std::optional<std::size_t> builtin_triangle_count(std::string_view source);

// Parses a count such as "8M", "250k" or "1000"; throws SceneError naming `what`.
std::size_t parse_triangle_count(std::string_view text, std::string_view what);

}  // namespace wavetrace
