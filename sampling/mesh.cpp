#include "sampling/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include <Eigen/Geometry>

#include "common/errors.hpp"

namespace mw {

namespace {
std::string describe(const TriangleMesh& mesh) { return mesh.source.empty() ? std::string("mesh") : mesh.source; }

// Index of the first vertex that is not finite or lies outside ±kMaxCoordinate, or -1.
long first_out_of_range(const std::vector<Vec3d>& vertices) {
    for (std::size_t i = 0; i < vertices.size(); ++i)
        if (!vertices[i].allFinite() || vertices[i].cwiseAbs().maxCoeff() > kMaxCoordinate) return static_cast<long>(i);
    return -1;
}

// Largest |coordinate| over the vertices.
double largest_coordinate(const std::vector<Vec3d>& vertices) {
    double largest = 0;
    for (const Vec3d& v : vertices) largest = std::max(largest, v.cwiseAbs().maxCoeff());
    return largest;
}

bool too_far_to_resolve(double largest, double size) { return size > 0 && largest > kMaxDistanceInMeshSizes * size; }
}  // namespace

bool MeshTransform::is_identity() const {
    return scale == Vec3d(1, 1, 1) && rotation_deg == Vec3d::Zero() && translation == Vec3d::Zero();
}

void apply_transform(TriangleMesh& mesh, const MeshTransform& tr) {
    for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(tr.scale[k]) || tr.scale[k] == 0.0) {
            std::ostringstream s;
            s << describe(mesh) << ": transform scale must be finite and non-zero (got " << tr.scale.transpose() << ")";
            throw InputError(s.str());
        }
        if (!std::isfinite(tr.rotation_deg[k]) || !std::isfinite(tr.translation[k]))
            throw InputError(describe(mesh) + ": transform rotation and translation must be finite");
    }
    const double d2r = M_PI / 180.0;
    const Eigen::Matrix3d rot = (Eigen::AngleAxisd(tr.rotation_deg.z() * d2r, Vec3d::UnitZ()) *
                                 Eigen::AngleAxisd(tr.rotation_deg.y() * d2r, Vec3d::UnitY()) *
                                 Eigen::AngleAxisd(tr.rotation_deg.x() * d2r, Vec3d::UnitX()))
                                    .toRotationMatrix();
    // Into a copy, so that a transform refused below leaves the mesh as it was.
    std::vector<Vec3d> moved(mesh.vertices.size());
    Aabb unmoved;  // the scaled and rotated mesh, before the translation
    for (std::size_t i = 0; i < moved.size(); ++i) {
        const Vec3d turned = rot * mesh.vertices[i].cwiseProduct(tr.scale);
        unmoved.lo = i ? unmoved.lo.cwiseMin(turned) : turned;
        unmoved.hi = i ? unmoved.hi.cwiseMax(turned) : turned;
        moved[i] = turned + tr.translation;
    }
    auto describe_transform = [&](std::ostream& s) {
        s << "(scale " << tr.scale.x() << "," << tr.scale.y() << "," << tr.scale.z() << ", rotation " << tr.rotation_deg.x()
          << "," << tr.rotation_deg.y() << "," << tr.rotation_deg.z() << ", translation " << tr.translation.x() << ","
          << tr.translation.y() << "," << tr.translation.z() << ")";
    };
    // A mesh that was out of range before is validate_mesh's to report: the transform is not to blame.
    const bool was_in_range = first_out_of_range(mesh.vertices) < 0 &&
                              !too_far_to_resolve(largest_coordinate(mesh.vertices), bounding_box(mesh).extent().norm());
    const long bad = was_in_range ? first_out_of_range(moved) : -1;
    if (bad >= 0) {
        const Vec3d& v = moved[static_cast<std::size_t>(bad)];
        std::ostringstream s;
        s << describe(mesh) << ": the transform ";
        describe_transform(s);
        s << " takes vertex " << bad + 1 << " to (" << v.x() << ", " << v.y() << ", " << v.z()
          << "), outside the range of +-" << kMaxCoordinate << " that coordinates must lie in";
        throw InputError(s.str());
    }
    const double size = unmoved.extent().norm(), largest = largest_coordinate(moved);
    if (was_in_range && too_far_to_resolve(largest, size)) {
        std::ostringstream s;
        s << describe(mesh) << ": the transform ";
        describe_transform(s);
        s << " puts the mesh (size " << size << ") " << largest << " from the origin, too far for double precision "
          << "to resolve it (at most " << kMaxDistanceInMeshSizes << " times its size)";
        throw InputError(s.str());
    }
    mesh.vertices = std::move(moved);
    if (tr.scale.x() * tr.scale.y() * tr.scale.z() < 0) flip_orientation(mesh);
}

Aabb bounding_box(const TriangleMesh& mesh) {
    Aabb b;
    if (mesh.vertices.empty()) return b;
    b.lo = b.hi = mesh.vertices[0];
    for (const Vec3d& v : mesh.vertices) {
        b.lo = b.lo.cwiseMin(v);
        b.hi = b.hi.cwiseMax(v);
    }
    return b;
}

double signed_volume(const TriangleMesh& mesh) {
    // About the origin: for a closed mesh the point does not matter, for an open one this is the
    // usual cone closure towards the origin (what mesh tools report).
    double v = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        v += mesh.corner(t, 0).dot(mesh.corner(t, 1).cross(mesh.corner(t, 2)));
    return v / 6.0;
}

double triangle_area(const TriangleMesh& mesh, std::size_t t) {
    return 0.5 * (mesh.corner(t, 1) - mesh.corner(t, 0)).cross(mesh.corner(t, 2) - mesh.corner(t, 0)).norm();
}

double surface_area(const TriangleMesh& mesh) {
    double a = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) a += triangle_area(mesh, t);
    return a;
}

Vec3d triangle_normal(const TriangleMesh& mesh, std::size_t t) {
    const Vec3d n = (mesh.corner(t, 1) - mesh.corner(t, 0)).cross(mesh.corner(t, 2) - mesh.corner(t, 0));
    const double len = n.norm();
    return len > 0 ? Vec3d(n / len) : Vec3d::Zero();
}

EdgeReport edge_report(const TriangleMesh& mesh) {
    // Per undirected edge: number of uses, and uses in the a<b direction.
    std::unordered_map<std::uint64_t, std::pair<int, int>> count;
    count.reserve(mesh.triangles.size() * 2);
    for (const auto& tri : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            std::uint64_t a = static_cast<std::uint32_t>(tri[k]), b = static_cast<std::uint32_t>(tri[(k + 1) % 3]);
            if (a == b) continue;
            const bool forward = a < b;
            if (!forward) std::swap(a, b);
            auto& c = count[(a << 32) | b];
            ++c.first;
            if (forward) ++c.second;
        }
    EdgeReport r;
    for (const auto& kv : count) {
        if (kv.second.first == 1) ++r.boundary_edges;
        if (kv.second.first > 2) ++r.nonmanifold_edges;
        if (kv.second.first == 2 && kv.second.second != 1) ++r.misoriented_edges;
    }
    return r;
}

void flip_orientation(TriangleMesh& mesh) {
    for (auto& tri : mesh.triangles) std::swap(tri[1], tri[2]);
}

TriangleMesh without_unused_vertices(const TriangleMesh& mesh) {
    TriangleMesh out;
    out.source = mesh.source;
    std::vector<int> new_index(mesh.vertices.size(), -1);
    for (const auto& tri : mesh.triangles) {
        std::array<int, 3> renumbered;
        for (int k = 0; k < 3; ++k) {
            int& id = new_index[static_cast<std::size_t>(tri[k])];
            if (id < 0) {
                id = static_cast<int>(out.vertices.size());
                out.vertices.push_back(mesh.vertices[static_cast<std::size_t>(tri[k])]);
            }
            renumbered[k] = id;
        }
        out.triangles.push_back(renumbered);
    }
    return out;
}

void validate_mesh(const TriangleMesh& mesh, bool require_volume) {
    const std::string src = describe(mesh);
    if (mesh.triangles.empty()) throw InputError(src + ": the mesh has no triangles");
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3d& v = mesh.vertices[i];
        if (!v.allFinite()) {
            std::ostringstream s;
            s << src << ": vertex " << i + 1 << " is not finite (" << v.x() << ", " << v.y() << ", " << v.z() << ")";
            throw InputError(s.str());
        }
    }
    const long nv = static_cast<long>(mesh.vertices.size());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k)
            if (mesh.triangles[t][k] < 0 || mesh.triangles[t][k] >= nv) {
                std::ostringstream s;
                s << src << ": triangle " << t + 1 << " refers to vertex " << mesh.triangles[t][k] + 1 << " but the mesh has "
                  << nv << " vertices";
                throw InputError(s.str());
            }
    const long far = first_out_of_range(mesh.vertices);
    if (far >= 0) {
        const Vec3d& v = mesh.vertices[static_cast<std::size_t>(far)];
        std::ostringstream s;
        s << src << ": vertex " << far + 1 << " (" << v.x() << ", " << v.y() << ", " << v.z()
          << ") is out of range: coordinates must lie within +-" << kMaxCoordinate;
        throw InputError(s.str());
    }
    const Aabb box = bounding_box(mesh);
    const Vec3d e = box.extent();
    const double largest = largest_coordinate(mesh.vertices);
    if (too_far_to_resolve(largest, e.norm())) {
        std::ostringstream s;
        s << src << ": the mesh (size " << e.norm() << ") lies " << largest << " from the origin, too far for double "
          << "precision to resolve it (at most " << kMaxDistanceInMeshSizes << " times its size)";
        throw InputError(s.str());
    }
    if (!require_volume) return;
    const double box_volume = e.x() * e.y() * e.z();
    const double vol = std::abs(signed_volume(mesh));
    if (!(box_volume > 0) || !(vol > 1e-9 * box_volume)) {
        std::ostringstream s;
        s << src << ": the mesh encloses zero volume (signed volume " << signed_volume(mesh) << ", bounding box "
          << e.x() << " x " << e.y() << " x " << e.z() << ")";
        throw InputError(s.str());
    }
}

}  // namespace mw
