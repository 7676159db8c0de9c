// Triangle meshes on the host, in double precision: the input of every sampler in sampling/.
// A mesh is a vertex list and a triangle list (counter-clockwise seen from outside = outward
// normal). Validation throws InputError with one line naming the source and the problem.
#pragma once
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace mw {

using Vec3d = Eigen::Vector3d;

struct Aabb {
    Vec3d lo{0, 0, 0}, hi{0, 0, 0};
    Vec3d extent() const { return hi - lo; }
    Vec3d center() const { return 0.5 * (lo + hi); }
};

struct TriangleMesh {
    std::vector<Vec3d> vertices;
    std::vector<std::array<int, 3>> triangles;
    std::string source;  // file path or procedural description, used in error messages

    std::size_t vertex_count() const { return vertices.size(); }
    std::size_t triangle_count() const { return triangles.size(); }
    Vec3d corner(std::size_t t, int k) const { return vertices[static_cast<std::size_t>(triangles[t][k])]; }
};

// Largest |coordinate| a mesh vertex may have. Particles are stored and written in single
// precision (largest float about 3.4e38) and the sampler cubes coordinates (volumes) in double:
// 1e30 leaves room for both, and for the spacing and support radius around the mesh.
constexpr double kMaxCoordinate = 1e30;
// How far from the origin a mesh may lie, in units of its size (bounding-box diagonal). Double
// precision resolves about 1e-16 of a coordinate; the sampler needs positions (lattice points,
// ray origins) to about 1e-7 of the mesh's size, which holds up to 1e9 sizes away.
constexpr double kMaxDistanceInMeshSizes = 1e9;

// Scale first, then rotate (Euler angles in degrees about x, then y, then z), then translate.
struct MeshTransform {
    Vec3d scale{1, 1, 1};
    Vec3d rotation_deg{0, 0, 0};
    Vec3d translation{0, 0, 0};
    bool is_identity() const;
};

// Applies the transform in place. A mirroring scale (odd number of negative factors) also flips
// the winding so normals stay outward. Throws InputError (leaving the mesh unchanged) on a zero
// or non-finite scale, or when a transformed vertex leaves ±kMaxCoordinate or the mesh ends up
// farther than kMaxDistanceInMeshSizes of its sizes from the origin.
void apply_transform(TriangleMesh& mesh, const MeshTransform& transform);

Aabb bounding_box(const TriangleMesh& mesh);
// Signed volume by the divergence theorem (positive for an outward-oriented closed mesh). For an
// open mesh it is the volume of the cone closure towards the origin, as usual.
double signed_volume(const TriangleMesh& mesh);
double surface_area(const TriangleMesh& mesh);
double triangle_area(const TriangleMesh& mesh, std::size_t t);
// Unit outward normal of triangle t (zero vector for a degenerate triangle).
Vec3d triangle_normal(const TriangleMesh& mesh, std::size_t t);
// Edges used by exactly one triangle (holes) and by more than two (non-manifold).
struct EdgeReport {
    std::size_t boundary_edges = 0;
    std::size_t nonmanifold_edges = 0;
    std::size_t misoriented_edges = 0;  // two triangles traverse the edge in the same direction
    bool closed() const { return boundary_edges == 0 && nonmanifold_edges == 0; }
    bool consistently_oriented() const { return misoriented_edges == 0; }
};
EdgeReport edge_report(const TriangleMesh& mesh);
void flip_orientation(TriangleMesh& mesh);
// The same triangles over only the vertices they use (renumbered in order of first use). Indices
// must be in range (validate_mesh).
TriangleMesh without_unused_vertices(const TriangleMesh& mesh);

// Checks that the mesh can be sampled: at least one triangle, finite vertices within
// ±kMaxCoordinate, indices in range, not farther than kMaxDistanceInMeshSizes of its sizes from
// the origin, and (when require_volume) a non-zero enclosed volume. Throws InputError
// "<source>: <problem>".
void validate_mesh(const TriangleMesh& mesh, bool require_volume = true);

}  // namespace mw
