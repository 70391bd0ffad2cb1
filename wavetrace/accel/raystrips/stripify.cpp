// The choice between the two stripifiers, by name.
#include "wavetrace/accel/raystrips/stripify.hpp"

#include <stdexcept>

namespace wavetrace {

StripifierKind parse_stripifier(const std::string& text) {
  if (text == "dual_path") return StripifierKind::dual_path;
  if (text == "openmesh") return StripifierKind::openmesh;
  throw std::invalid_argument("unknown stripifier '" + text + "' (dual_path, openmesh)");
}

std::string to_string(StripifierKind kind) { return kind == StripifierKind::dual_path ? "dual_path" : "openmesh"; }

std::vector<TriangleStrip> stripify(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                    StripifierKind kind, std::uint32_t max_triangles) {
  return kind == StripifierKind::dual_path ? stripify_dual_path(mesh, triangles, max_triangles)
                                           : stripify_openmesh(mesh, triangles, max_triangles);
}

}  // namespace wavetrace
