#include "pixelgym/render/mesh_data.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <utility>

namespace pixelgym::render {
namespace {

// Every triangle faces outward (its winding normal points away from the centre) and the vertex
// normals are unit length: the renderer's lighting depends on both.
void expect_closed_outward(const MeshData& mesh) {
  ASSERT_EQ(mesh.positions.size(), mesh.normals.size());
  ASSERT_EQ(mesh.indices.size() % 3, 0U);
  for (const Eigen::Vector3f& n : mesh.normals) ASSERT_NEAR(n.norm(), 1.0F, 1e-4F);
  for (std::size_t i = 0; i < mesh.indices.size(); i += 3) {
    const Eigen::Vector3f& a = mesh.positions[mesh.indices[i]];
    const Eigen::Vector3f& b = mesh.positions[mesh.indices[i + 1]];
    const Eigen::Vector3f& c = mesh.positions[mesh.indices[i + 2]];
    const Eigen::Vector3f face = (b - a).cross(c - a);
    if (face.norm() < 1e-9F) continue;  // degenerate triangles at poles
    ASSERT_GT(face.dot((a + b + c) / 3.0F), 0.0F) << "triangle " << i / 3 << " faces inward";
  }
}

TEST(MeshDataTest, PrimitivesAreClosedAndFaceOutward) {
  for (const auto& mesh :
       {make_box_mesh(), make_sphere_mesh(), make_sphere_mesh(10), make_cylinder_mesh(),
        make_cylinder_mesh(10), make_capsule_mesh(3.0), make_capsule_mesh(0.0, 10)}) {
    expect_closed_outward(*mesh);
    EXPECT_TRUE(mesh->closed);
    EXPECT_TRUE(is_closed_surface(*mesh));
  }
}

TEST(MeshDataTest, OpenOrInsideOutSurfacesAreNotClosed) {
  const MeshData box = *make_box_mesh();
  MeshData open = box;  // one triangle missing
  open.indices.resize(open.indices.size() - 3);
  EXPECT_FALSE(is_closed_surface(open));
  MeshData inside_out = box;  // every triangle wound the other way
  for (std::size_t i = 0; i < inside_out.indices.size(); i += 3) {
    std::swap(inside_out.indices[i + 1], inside_out.indices[i + 2]);
  }
  EXPECT_FALSE(is_closed_surface(inside_out));
  MeshData one_flipped = box;  // inconsistent winding
  std::swap(one_flipped.indices[1], one_flipped.indices[2]);
  EXPECT_FALSE(is_closed_surface(one_flipped));
  MeshData doubled = box;  // a face drawn twice
  doubled.indices.insert(doubled.indices.end(), box.indices.begin(), box.indices.begin() + 3);
  EXPECT_FALSE(is_closed_surface(doubled));
  EXPECT_FALSE(is_closed_surface(MeshData{}));
  EXPECT_FALSE(MeshData{}.closed);
}

TEST(MeshDataTest, ClusteringKeepsTheClosedFlag) {
  EXPECT_TRUE(simplify_by_clustering(*make_sphere_mesh(), 0.5F)->closed);
  MeshData open = *make_sphere_mesh();
  open.closed = false;
  EXPECT_FALSE(simplify_by_clustering(open, 0.5F)->closed);
}

TEST(MeshDataTest, PrimitiveExtents) {
  const auto extent = [](const MeshData& mesh) {
    Eigen::AlignedBox3f box;
    for (const Eigen::Vector3f& p : mesh.positions) box.extend(p);
    return Eigen::Vector3f(box.sizes());
  };
  EXPECT_TRUE(extent(*make_box_mesh()).isApprox(Eigen::Vector3f(1, 1, 1), 1e-6F));
  EXPECT_TRUE(extent(*make_sphere_mesh()).isApprox(Eigen::Vector3f(2, 2, 2), 1e-3F));
  EXPECT_TRUE(extent(*make_cylinder_mesh()).isApprox(Eigen::Vector3f(2, 2, 1), 1e-3F));
  EXPECT_TRUE(extent(*make_capsule_mesh(3.0)).isApprox(Eigen::Vector3f(2, 2, 5), 1e-3F));
}

}  // namespace
}  // namespace pixelgym::render
