#include "sampling/embree_mesh.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <omp.h>

namespace mw {

EmbreeMesh::EmbreeMesh(const TriangleMesh& mesh, RTCFilterFunctionN intersect_filter) {
    const Aabb box = bounding_box(mesh);
    center_ = box.center();
    const double diagonal = box.extent().norm();
    reach_ = diagonal > 0 && std::isfinite(diagonal) ? diagonal : 1.0;
    unit_ = std::ldexp(1.0, std::ilogb(reach_));
    const std::string config = "verbose=0,threads=" + std::to_string(omp_get_max_threads());
    device_ = rtcNewDevice(config.c_str());
    if (!device_) throw std::runtime_error("Embree: cannot create a device");
    scene_ = rtcNewScene(device_);
    rtcSetSceneFlags(scene_, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene_, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geom = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    float* v = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), mesh.vertices.size()));
    for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
        const Vec3d p = to_embree(mesh.vertices[i]);
        v[3 * i] = float(p.x());
        v[3 * i + 1] = float(p.y());
        v[3 * i + 2] = float(p.z());
    }
    unsigned* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                                   3 * sizeof(unsigned), mesh.triangles.size()));
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        for (int k = 0; k < 3; ++k) idx[3 * t + k] = static_cast<unsigned>(mesh.triangles[t][k]);
    if (intersect_filter) rtcSetGeometryIntersectFilterFunction(geom, intersect_filter);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene_, geom);
    rtcReleaseGeometry(geom);
    rtcCommitScene(scene_);
    if (rtcGetDeviceError(device_) != RTC_ERROR_NONE) {
        release();
        throw std::runtime_error("Embree: building the scene failed");
    }
}

EmbreeMesh::~EmbreeMesh() { release(); }

void EmbreeMesh::release() {
    if (scene_) rtcReleaseScene(scene_);
    if (device_) rtcReleaseDevice(device_);
    scene_ = nullptr;
    device_ = nullptr;
}

}  // namespace mw
