#include "sampling/surface_inset.hpp"

#include <cmath>
#include <limits>

#include <embree3/rtcore.h>

#include "common/errors.hpp"
#include "sampling/embree_mesh.hpp"

namespace mw {

std::vector<double> surface_insets(const TriangleMesh& mesh, const SurfaceParticles& sbp, double depth) {
    if (!(depth >= 0) || !std::isfinite(depth)) throw InputError("surface inset: the depth must be finite and >= 0");
    std::vector<double> inset(sbp.count(), 0.0);
    if (depth == 0 || sbp.count() == 0) return inset;
    const EmbreeMesh embree(mesh);
    const double unit = embree.unit();
    // The ray starts on the SBP's own face: hits closer than this (its own triangle and, at an
    // edge, the neighbours it shares a point with) are the surface it starts on.
    const float skip = float(1e-3 * depth / unit);
#pragma omp parallel for schedule(static)
    for (long k = 0; k < static_cast<long>(sbp.count()); ++k) {
        // Only a face within twice the depth can matter.
        RTCRayHit rh = embree_ray(embree.to_embree(sbp.positions[std::size_t(k)]), -sbp.normals[std::size_t(k)], skip,
                                  float(2 * depth / unit));
        RTCIntersectContext context;
        rtcInitIntersectContext(&context);
        rtcIntersect1(embree.scene(), &context, &rh);
        const bool hit = rh.hit.geomID != RTC_INVALID_GEOMETRY_ID;
        const double half_thickness = hit ? 0.5 * double(rh.ray.tfar) * unit : depth;
        inset[std::size_t(k)] = half_thickness < depth ? half_thickness : depth;
    }
    return inset;
}

}  // namespace mw
