// Scene files and multi-object scenes: transforms, material indices, errors that name the
// object, and a scene of several real meshes that renders.
#include <gtest/gtest.h>

#include <algorithm>

#include <glm/geometric.hpp>

#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/object_transform.hpp"
#include "wavetrace/scene/scene_file.hpp"
#include "wavetrace/scene/subdivide.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

using testing::signed_volume;

using testing::write_temp_file;

// A right-angled tetrahedron with outward faces: corners at the origin and on the axes.
const char* kTetrahedronOff = "OFF\n4 4 0\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n";

std::string scene_file(const std::string& name, const std::string& body) {
  write_temp_file("tetrahedron.off", kTetrahedronOff);
  return write_temp_file(name, body);
}

void expect_near(const glm::vec3& actual, const glm::vec3& expected) {
  EXPECT_NEAR(actual.x, expected.x, 1e-5f);
  EXPECT_NEAR(actual.y, expected.y, 1e-5f);
  EXPECT_NEAR(actual.z, expected.z, 1e-5f);
}

TEST(SceneFile, ScaleRotateTranslateInThatOrder) {
  const Scene scene = load_scene_file(scene_file("transform.toml", R"(
[[object]]
mesh = "tetrahedron.off"
scale = [2, 3, 4]
rotate = [0, 90, 0]
translate = [10, 20, 30]
)"));
  ASSERT_EQ(scene.mesh.vertex_count(), 4u);
  // x-axis corner: scaled to (2,0,0), turned 90 degrees about y to (0,0,-2), then moved.
  expect_near(scene.mesh.positions[0], glm::vec3(10, 20, 30));
  expect_near(scene.mesh.positions[1], glm::vec3(10, 20, 28));
  expect_near(scene.mesh.positions[2], glm::vec3(10, 23, 30));
  expect_near(scene.mesh.positions[3], glm::vec3(14, 20, 30));
  EXPECT_NEAR(signed_volume(scene.mesh), 24.0 / 6.0, 1e-4);  // outward, 2*3*4 times 1/6
}

TEST(SceneFile, RotationsComposeAboutXThenYThenZ) {
  TriangleMesh mesh;
  mesh.positions = {glm::vec3(0, 1, 0)};
  ObjectTransform transform;
  transform.rotate_degrees = glm::vec3(90, 0, 90);  // y -> z about x, then z stays under z
  apply_transform(mesh, transform, "test");
  expect_near(mesh.positions[0], glm::vec3(0, 0, 1));
  mesh.positions = {glm::vec3(1, 0, 0)};
  apply_transform(mesh, transform, "test");  // x stays under x, then x -> y about z
  expect_near(mesh.positions[0], glm::vec3(0, 1, 0));
}

TEST(SceneFile, MirroringKeepsFacesOutward) {
  const Scene scene = load_scene_file(scene_file("mirror.toml", R"(
[[object]]
mesh = "tetrahedron.off"
scale = [-1, 1, 1]
)"));
  EXPECT_NEAR(signed_volume(scene.mesh), 1.0 / 6.0, 1e-6);
}

TEST(SceneFile, FitCentresAndScalesTheLargestExtent) {
  const Scene scene = load_scene_file(scene_file("fit.toml", R"(
[[object]]
mesh = "tetrahedron.off"
fit = 5
translate = [0, 1, 0]
)"));
  const Bounds3 bounds = scene.mesh.bounds();
  expect_near(bounds.extent(), glm::vec3(5.0f));
  expect_near(bounds.center(), glm::vec3(0, 1, 0));
}

TEST(SceneFile, MaterialIndicesFollowObjectsAndBuiltinsKeepTheirOwn) {
  const Scene scene = load_scene_file(scene_file("materials.toml", R"(
background = 0.5
[[object]]
name = "red"
mesh = "tetrahedron.off"
albedo = [0.9, 0.1, 0.1]
[[object]]
name = "default scene"
mesh = "builtin:default:80"
translate = [5, 0, 0]
[[light]]
corner = [0, 4, 0]
edge_u = [1, 0, 0]
edge_v = [0, 0, 1]
emission = 7
)"));
  const Scene builtin = make_builtin_scene("builtin:default:80");
  ASSERT_EQ(scene.mesh.triangle_count(), 4 + builtin.mesh.triangle_count() + 2);
  ASSERT_EQ(scene.materials.size(), 1 + builtin.materials.size() + 1);
  for (std::size_t t = 0; t < 4; ++t) EXPECT_EQ(scene.mesh.material(t), 0u);
  for (std::size_t t = 0; t < builtin.mesh.triangle_count(); ++t) {
    ASSERT_EQ(scene.mesh.material(4 + t), 1 + builtin.mesh.material(t));
  }
  EXPECT_EQ(scene.mesh.material(scene.mesh.triangle_count() - 1), scene.materials.size() - 1);
  EXPECT_EQ(scene.materials[0].albedo, glm::vec3(0.9f, 0.1f, 0.1f));
  EXPECT_EQ(scene.materials.back().emission, glm::vec3(7.0f));
  EXPECT_EQ(scene.background, glm::vec3(0.5f));
  // Each object and the light begin a chunk of their own in a chunked build.
  EXPECT_EQ(scene.object_starts, (std::vector<std::size_t>{0, 4, 4 + builtin.mesh.triangle_count()}));
  // Both the builtin's ceiling light and the file's light are emitters.
  EXPECT_EQ(LightSampler(scene).count(), 4u);
  // Facing down: the quad's normal is cross(edge_u, edge_v) = -y.
  const glm::uvec3 light = scene.mesh.triangles.back();
  const glm::vec3 normal = glm::cross(scene.mesh.positions[light.y] - scene.mesh.positions[light.x],
                                      scene.mesh.positions[light.z] - scene.mesh.positions[light.x]);
  EXPECT_LT(normal.y, 0.0f);
}

TEST(SceneFile, CameraComesFromTheFile) {
  const Scene scene = load_scene_file(scene_file("camera.toml", R"(
[camera]
position = [1, 2, 3]
look_at = [0, 0, 0]
up = [0, 0, 1]
fov = 30
[[object]]
mesh = "tetrahedron.off"
)"));
  ASSERT_TRUE(scene.camera.has_value());
  EXPECT_EQ(scene.camera->position, glm::vec3(1, 2, 3));
  EXPECT_EQ(scene.camera->up, glm::vec3(0, 0, 1));
  EXPECT_EQ(scene.camera->vertical_fov_degrees, 30.0f);
  const Camera resolved = resolve_camera(CameraOverride{}, scene);
  EXPECT_EQ(resolved.up, glm::vec3(0, 0, 1));  // the config's default does not override it
}

struct BadScene {
  std::string body;
  std::string message;
};
// ctest shows the message each case expects rather than the struct's bytes.
void PrintTo(const BadScene& scene, std::ostream* out) { *out << scene.message; }

class SceneFileErrors : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneFileErrors, NameTheObjectAndTheProblem) {
  // One file per case: ctest runs the cases in parallel.
  std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::replace(name.begin(), name.end(), '/', '_');
  const std::string path = scene_file(name + ".toml", GetParam().body);
  try {
    load_scene_file(path);
    FAIL() << "no error for:\n" << GetParam().body;
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find(GetParam().message), std::string::npos) << error.what();
  }
}

INSTANTIATE_TEST_SUITE_P(
    Cases, SceneFileErrors,
    ::testing::Values(
        BadScene{"[[object]]\nname = \"cat\"\nmesh = \"tetrahedron.off\"\ncolour = 1\n",
                 "object 'cat' (#1): unknown key 'colour'"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\n[[object]]\nname = \"ghost\"\nmesh = \"missing.off\"\n",
                 "object 'ghost' (#2): "},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nscale = [1, 0, 1]\n", "object #1: scale (1, 0, 1) is degenerate"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nscale = [1, nan, 1]\n", "scale must be"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nfit = -2\n", "fit = -2 must be a positive size"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nrotate = [1, 2]\n", "rotate must be [x, y, z]"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nalbedo = 1.5\n", "albedo components must be in [0, 1]"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nsubdivide = 9\n", "subdivide must be an integer in [0, 6]"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nmaterial = { type = \"metal\" }\n",
                 "object #1: material: unknown material type 'metal' (known: diffuse, mirror, glass)"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nmaterial = { type = \"glass\", ior = 0.5 }\n",
                 "object #1: material: ior must be in [1, 4]"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nmaterial = { type = \"mirror\", ior = 1.5 }\n",
                 "ior is for glass only"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nmaterial = { type = \"glass\", shine = 1 }\n",
                 "object #1: material: unknown key 'shine'"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nmaterial = \"glass\"\n", "material must be a table"},
        BadScene{"[[object]]\nmesh = \"tetrahedron.off\"\nalbedo = 0.5\nmaterial = { type = \"glass\" }\n",
                 "give albedo and emission inside 'material', not beside it"},
        BadScene{"[[object]]\nname = \"nameless\"\n", "object 'nameless' (#1): 'mesh' is required"},
        BadScene{"[[object]]\nmesh = \"other.toml\"\n", "a scene file cannot hold another scene file"},
        BadScene{"[[object]]\nmesh = \"builtin:teapot\"\n", "unknown builtin scene 'teapot'"},
        BadScene{"[[light]]\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\nedge_v = [2, 0, 0]\nemission = 1\n",
                 "light #1: edge_u and edge_v span no area"},
        BadScene{"[[light]]\ncorner = [0, 0, 0]\nedge_u = [1, 0, 0]\n", "light #1: 'edge_v' is required"},
        BadScene{"lights = 3\n", "unknown key 'lights'"}, BadScene{"background = 1\n", "the scene has no [[object]]"},
        BadScene{"[camera]\nposition = [0, 0, 0]\nlook_at = [0, 0, 0]\n[[object]]\nmesh = \"tetrahedron.off\"\n",
                 ".toml: camera: look_at equals position"},
        BadScene{"[[object]\nmesh = 1\n", ".toml:1:"}),
    [](const ::testing::TestParamInfo<BadScene>& info) { return "case" + std::to_string(info.index); });

TEST(SceneFile, MissingFileIsAnError) {
  EXPECT_THROW(load_scene({"/nonexistent/scene.toml", 0}), SceneError);
}

TEST(SceneFile, ObjectsPastTheTriangleBudgetAreRefusedBeforeTheyAreBuilt) {
  const std::string path = testing::write_temp_file(
      "budget.toml",
      "[[object]]\nmesh = \"builtin:sphere:1000\"\n[[object]]\nname = \"big\"\nmesh = \"builtin:sphere:2G\"\nsubdivide = 6\n");
  try {
    load_scene_file(path, SceneFileLimits{.max_triangles = 5000});
    FAIL() << "a 2G-triangle object subdivided 6 times was built";
  } catch (const SceneError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("object 'big' (#2): makes 8.192e+12 triangles subdivided 6 times"), std::string::npos) << message;
    EXPECT_NE(message.find("past what the scene may hold (5000 in all, 4000 left"), std::string::npos) << message;
  }
  // The default budget is the machine's memory: the same file is refused without a limit.
  EXPECT_THROW(load_scene_file(path), SceneError);
  // A default-sized builtin is charged its default count (200k for default) before it is made.
  const std::string small = testing::write_temp_file("small_budget.toml", "[[object]]\nmesh = \"builtin:default\"\n");
  EXPECT_THROW(load_scene_file(small, SceneFileLimits{.max_triangles = 1000}), SceneError);
  EXPECT_EQ(builtin_triangle_count("builtin:default"), std::optional<std::size_t>(200000));
  EXPECT_EQ(builtin_triangle_count("builtin:room:10"), std::optional<std::size_t>(2000)) << "the room's floor";
}

TEST(SceneFile, SubdivisionKeepsEachTrianglesMaterial) {
  const Scene scene = load_scene({"builtin:default:80", 1});
  ASSERT_EQ(scene.mesh.material_of_triangle.size(), scene.mesh.triangle_count());
  EXPECT_EQ(LightSampler(scene).count(), 2u * 4);  // the ceiling quad, subdivided once
}

TEST(SceneFile, GalleryOfRealMeshesRenders) {
  const Scene scene = load_scene({std::string(WAVETRACE_SOURCE_DIR) + "/scenes/gallery.toml", 0});
  EXPECT_GT(scene.mesh.triangle_count(), 200000u);
  EXPECT_GE(scene.materials.size(), 5u);
  Config config;
  config.set("render.width=40");
  config.set("render.height=30");
  config.set("render.spp=2");
  const RenderPlan plan = plan_render(config);
  const auto accelerator = make_accelerator(scene.mesh, plan.accelerator);
  const LightSampler lights(scene);
  const RenderOutput output = render_image(plan, World{scene, *accelerator, lights}, resolve_camera(plan.camera, scene));
  ASSERT_FALSE(output.hit_rates.empty());
  EXPECT_GT(output.hit_rates[0].rate(), 0.3);  // the camera sees the meshes and the plinth
  double sum = 0.0;
  for (float value : output.image) sum += value;
  EXPECT_GT(sum / double(output.image.size()), 0.01);
}

}  // namespace
}  // namespace wavetrace
