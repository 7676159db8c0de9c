// The rotational part of a 3×3 matrix, robust and warm-started, usable in kernels on both backends.
//
// Method (after Müller, Bender, Chentanez and Macklin 2016, "A robust method to extract the
// rotational part of deformations"): keep the rotation as a unit quaternion q and repeatedly turn
// it about the axis ω = Σ_k r_k × a_k / (|Σ_k r_k · a_k| + ε), where r_k, a_k are the columns of
// R(q) and A. At a fixed point Σ_k r_k × a_k = 0, i.e. Rᵀ A is symmetric: R is the polar rotation
// (when Rᵀ A is also positive definite, which warm-starting from last step's rotation keeps).
// Unlike SVD or Newton iterations it never divides by det A, so flat (rank 2) and line-like
// (rank 1) regions of thin parts are fine: the undetermined part of the rotation simply stays at
// its warm start. Starting from the identity with a symmetric A it returns exactly the identity,
// which keeps a body at rest bitwise at rest.
#pragma once
#include <cmath>

#include "algorithms/vec3.hpp"

namespace mw {

struct Quat {
    Real w, x, y, z;
};

MW_INLINE Quat quat_identity() { return Quat{1, 0, 0, 0}; }

MW_INLINE Quat quat_mul(Quat a, Quat b) {
    return Quat{a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z, a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
                a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x, a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w};
}

MW_INLINE Quat quat_normalized(Quat q) {
    const Real n2 = q.w * q.w + q.x * q.x + q.y * q.y + q.z * q.z;
    if (!(n2 > Real(0))) return quat_identity();
    const Real s = Real(1) / std::sqrt(n2);
    return Quat{q.w * s, q.x * s, q.y * s, q.z * s};
}

// Rotation matrix of a unit quaternion (exactly the identity for (1, 0, 0, 0)).
MW_INLINE Mat3 quat_to_mat3(Quat q) {
    const Real xx = q.x * q.x, yy = q.y * q.y, zz = q.z * q.z;
    const Real xy = q.x * q.y, xz = q.x * q.z, yz = q.y * q.z;
    const Real wx = q.w * q.x, wy = q.w * q.y, wz = q.w * q.z;
    return Mat3{{{1 - 2 * (yy + zz), 2 * (xy - wz), 2 * (xz + wy)},
                 {2 * (xy + wz), 1 - 2 * (xx + zz), 2 * (yz - wx)},
                 {2 * (xz - wy), 2 * (yz + wx), 1 - 2 * (xx + yy)}}};
}

// Rotates v by the unit quaternion q (same as quat_to_mat3(q) * v, fewer operations).
MW_INLINE Vec3 quat_rotate(Quat q, Vec3 v) {
    const Vec3 u{q.x, q.y, q.z};
    const Vec3 t = Real(2) * cross(u, v);
    return v + q.w * t + cross(u, t);
}

MW_INLINE Vec3 mat3_column(const Mat3& a, int k) { return Vec3{a.m[0][k], a.m[1][k], a.m[2][k]}; }

// Polar rotation of A, starting from `warm` (last step's result). Stops when the correction angle
// is below `tolerance` radians or after `max_iterations`.
MW_INLINE Quat polar_rotation(const Mat3& A, Quat warm, int max_iterations = 20, Real tolerance = Real(1e-7)) {
    Real scale = 0;  // Frobenius norm, for a scale-free ε
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) scale += A.m[i][j] * A.m[i][j];
    scale = std::sqrt(scale);
    Quat q = quat_normalized(warm);
    if (!(scale > Real(0)) || !(scale < Real(1e30))) return q;  // no information (or non-finite): keep
    const Real eps = Real(1e-9) * scale;
    const Vec3 a0 = mat3_column(A, 0), a1 = mat3_column(A, 1), a2 = mat3_column(A, 2);
    for (int it = 0; it < max_iterations; ++it) {
        const Mat3 R = quat_to_mat3(q);
        const Vec3 r0 = mat3_column(R, 0), r1 = mat3_column(R, 1), r2 = mat3_column(R, 2);
        const Vec3 num = cross(r0, a0) + cross(r1, a1) + cross(r2, a2);
        const Real den = std::fabs(dot(r0, a0) + dot(r1, a1) + dot(r2, a2)) + eps;
        const Vec3 omega = num / den;
        const Real angle = norm(omega);
        if (!(angle >= tolerance)) break;  // converged (also stops on NaN)
        const Real half = Real(0.5) * angle;
        const Real s = std::sin(half) / angle;
        q = quat_normalized(quat_mul(Quat{std::cos(half), omega.x * s, omega.y * s, omega.z * s}, q));
    }
    return q;
}

}  // namespace mw
