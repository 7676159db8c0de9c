// One triangle mesh in an Embree scene (a device and a BVH of its triangles), shared by the
// inside/outside ray casts (inside_outside.cpp) and the closest-point queries of the signed
// distance grids (signed_distance.cpp).
//
// Vertices are handed to Embree as floats relative to the bounding-box centre, so that meshes far
// from the origin keep their precision, and divided by a power of two close to the mesh's size:
// Embree's triangle test multiplies three coordinates together in single precision, which
// overflows for meshes larger than about 1e12 and underflows for ones smaller than about 1e-12 in
// their own units. A power of two scales every float operation exactly, so meshes of ordinary
// size get bit-for-bit the crossings they had unscaled.
#pragma once
#include <embree3/rtcore.h>

#include "sampling/mesh.hpp"

namespace mw {

// A ray from `origin` along `direction` (both in Embree's coordinates) over [tnear, tfar], with
// no hit recorded yet.
inline RTCRayHit embree_ray(const Vec3d& origin, const Vec3d& direction, float tnear, float tfar) {
    RTCRayHit rh;
    rh.ray.org_x = float(origin.x());
    rh.ray.org_y = float(origin.y());
    rh.ray.org_z = float(origin.z());
    rh.ray.dir_x = float(direction.x());
    rh.ray.dir_y = float(direction.y());
    rh.ray.dir_z = float(direction.z());
    rh.ray.tnear = tnear;
    rh.ray.tfar = tfar;
    rh.ray.time = 0.f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

class EmbreeMesh {
public:
    // `intersect_filter`, when given, is attached to the triangles (called for every ray hit).
    // Embree builds its tree on its own (TBB) threads, held to the OpenMP thread count, so that
    // `--threads` bounds the whole sampler. Throws std::runtime_error when Embree fails.
    explicit EmbreeMesh(const TriangleMesh& mesh, RTCFilterFunctionN intersect_filter = nullptr);
    ~EmbreeMesh();
    EmbreeMesh(const EmbreeMesh&) = delete;
    EmbreeMesh& operator=(const EmbreeMesh&) = delete;

    RTCScene scene() const { return scene_; }
    // Embree's coordinates of a point, and lengths in them.
    Vec3d to_embree(const Vec3d& p) const { return (p - center_) / unit_; }
    double unit() const { return unit_; }    // the power of two Embree's coordinates are measured in
    double reach() const { return reach_; }  // bounding-box diagonal
    const Vec3d& center() const { return center_; }

private:
    void release();
    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    Vec3d center_;
    double reach_ = 1;
    double unit_ = 1;
};

}  // namespace mw
