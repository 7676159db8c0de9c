#include "sampling/mesh.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include <Eigen/Geometry>

#include "backend/errors.hpp"

namespace mw {

namespace {
std::string describe(const TriangleMesh& mesh) { return mesh.source.empty() ? std::string("mesh") : mesh.source; }
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
    for (Vec3d& v : mesh.vertices) v = rot * v.cwiseProduct(tr.scale) + tr.translation;
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
    if (!require_volume) return;
    const Aabb box = bounding_box(mesh);
    const Vec3d e = box.extent();
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
