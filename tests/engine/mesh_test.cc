#include "pixelgym/engine/mesh.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pixelgym/engine/robot_model.h"

namespace pixelgym::engine {
namespace {

using ::testing::HasSubstr;

std::string data(const std::string& name) {
  return std::string(PIXELGYM_SOURCE_DIR) + "/tests/data/" + name;
}

std::string error_of(const std::string& path) {
  try {
    load_mesh(path);
  } catch (const std::runtime_error& error) {
    return error.what();
  }
  return "(no exception)";
}

TEST(MeshTest, LoadsObjWithMaterialColoursFromItsMtl) {
  const auto mesh = load_mesh(asset_path("arm/meshes/link2.obj"));
  EXPECT_EQ(mesh->triangle_count(), 1152U);
  EXPECT_EQ(mesh->positions.size(), mesh->normals.size());
  ASSERT_EQ(mesh->parts.size(), 2U);  // shell and accent
  EXPECT_TRUE(mesh->parts[0].has_color);
  EXPECT_NEAR(mesh->parts[0].rgba.x(), 0.92F, 1e-3F);  // shell, from arm.mtl
  EXPECT_NEAR(mesh->parts[1].rgba.y(), 0.5F, 1e-3F);   // accent
  for (const Eigen::Vector3f& n : mesh->normals) ASSERT_NEAR(n.norm(), 1.0F, 1e-3F);
  EXPECT_GT(mesh->bounds.max().z(), 0.2F);
}

TEST(MeshTest, LoadsBinaryStl) {
  const auto mesh = load_mesh(asset_path("arm/meshes/link1_collision.stl"));
  EXPECT_GT(mesh->triangle_count(), 100U);
  EXPECT_LT(mesh->triangle_count(), 200U);
}

TEST(MeshTest, LoadsColladaWithItsColour) {
  const auto mesh = load_mesh(asset_path("arm/meshes/pedestal.dae"));
  EXPECT_EQ(mesh->triangle_count(), 128U);
  ASSERT_EQ(mesh->parts.size(), 1U);
  EXPECT_NEAR(mesh->parts[0].rgba.x(), 0.2F, 1e-3F);
  // Z_UP file: the pedestal stands 0.16 m tall along z.
  EXPECT_NEAR(mesh->bounds.max().z() - mesh->bounds.min().z(), 0.16F, 1e-4F);
}

TEST(MeshTest, BadFilesAreRefusedNamingFileAndProblem) {
  EXPECT_THAT(error_of(data("meshes/does_not_exist.obj")),
              HasSubstr("cannot be read (No such file or directory)"));
  EXPECT_THAT(error_of(data("meshes/shape.xyz")), HasSubstr("unsupported format \".xyz\""));
  EXPECT_THAT(error_of(data("meshes/no_triangles.obj")), HasSubstr("no triangles"));
  EXPECT_THAT(error_of(data("meshes/garbage.stl")), HasSubstr("garbage.stl"));
}

// Found by fuzz/mesh_fuzz.cc: a 254-byte PLY whose header assimp 5.2 reads forever (a "property"
// line of bytes that are no type). Refused from the header, before assimp sees it.
TEST(MeshTest, APlyHeaderAssimpWouldHangOnIsRefused) {
  EXPECT_THAT(error_of(data("meshes/hangs_assimp.ply")),
              HasSubstr("hangs_assimp.ply: malformed PLY header at line 3: expected \"element "
                        "NAME COUNT\""));
}

// A PLY whose ASCII body is garbled (found by fuzz/mesh_fuzz): assimp's reader built a face
// without vertices, and its Triangulate step then called abort(), ending the process.
TEST(MeshTest, AFaceWithoutVerticesIsRefusedBeforeAssimpPostProcessesIt) {
  EXPECT_THAT(error_of(data("meshes/face_without_vertices.ply")),
              HasSubstr("face_without_vertices.ply: face 0 of mesh 0 has no vertices"));
}

TEST(MeshCacheTest, ReadsEachFileOnce) {
  MeshCache cache;
  const auto a = cache.get(asset_path("arm/meshes/link3.obj"));
  const auto b =
      cache.get(std::string(PIXELGYM_SOURCE_DIR) + "/assets/arm/../arm/meshes/link3.obj");
  EXPECT_EQ(a.get(), b.get());
  EXPECT_EQ(cache.files_read(), 1);
}

}  // namespace
}  // namespace pixelgym::engine
