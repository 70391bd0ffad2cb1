// The text and STL mesh formats, each read from the file's bytes into a LoadedMesh's
// positions and triangles (polygons fanned from their first corner: v0, vk, vk+1).
//
// These readers are ours rather than OpenMesh's: OpenMesh's OFF and OBJ readers leave a
// field that does not parse uninitialized (a face then references a vertex that changes from
// run to run), read past comments they do not expect, and report no line. Ours check every
// field they use and throw SceneError "PATH line N: what was wrong"; fields they do not use
// (normals, colours, texture coordinates) are skipped unread.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include "wavetrace/scene/loaded_mesh.hpp"

namespace wavetrace {

// Fans a polygon of 3 or more corners into `out`'s triangles and counts it if it had more.
void add_polygon(LoadedMesh& out, std::span<const std::uint32_t> corners);

// OFF (also COFF, NOFF, STOFF...): optional "# comments" anywhere, the keyword, then
// "V F [E]" (on the keyword's line or the next), V vertex lines "x y z [extras]", F face
// lines "n i0 ... i(n-1) [colour]" with 0-based indices. 4OFF, nOFF and binary OFF are refused.
void read_off(std::string_view text, const std::string& path, LoadedMesh& out);

// Wavefront OBJ: "v x y z [w | r g b]" and "f c0 c1 c2 ...", a corner being "i", "i/t",
// "i//n" or "i/t/n" with 1-based indices, negative ones counted back from the last vertex;
// other statements (vt, vn, g, o, s, usemtl, mtllib, l, p) are skipped.
void read_obj(std::string_view text, const std::string& path, LoadedMesh& out);

// STL, binary (an 80-byte header, a uint32 triangle count, then per triangle 12 floats,
// normal and three corners, and a 2-byte attribute: 84 + 50 n bytes in all) or ASCII
// ("solid", then "facet normal / outer loop / vertex x y z (x3) / endloop / endfacet",
// "endsolid"). STL repeats a vertex in every triangle that uses it; corners at the same
// position (+0 and -0 alike) become one vertex, so strips and subdivision see the surface.
void read_stl(std::string_view text, const std::string& path, LoadedMesh& out);

// ASCII PLY (ply_header.hpp): one record per line, elements in the header's order.
void read_text_ply(std::string_view text, const std::string& path, LoadedMesh& out);

}  // namespace wavetrace
