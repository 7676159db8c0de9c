// Small fixed-size vector and matrix types usable in kernels on both backends.
#pragma once
#include <cmath>

#include "backend/config.hpp"

namespace mw {

struct Vec3 {
    Real x, y, z;
};

MW_INLINE Vec3 make_vec3(Real x, Real y, Real z) { return Vec3{x, y, z}; }
MW_INLINE Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
MW_INLINE Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
MW_INLINE Vec3 operator-(Vec3 a) { return {-a.x, -a.y, -a.z}; }
MW_INLINE Vec3 operator*(Real s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
MW_INLINE Vec3 operator*(Vec3 a, Real s) { return {s * a.x, s * a.y, s * a.z}; }
MW_INLINE Vec3 operator/(Vec3 a, Real s) { return {a.x / s, a.y / s, a.z / s}; }
MW_INLINE Vec3& operator+=(Vec3& a, Vec3 b) {
    a.x += b.x;
    a.y += b.y;
    a.z += b.z;
    return a;
}
MW_INLINE Vec3& operator-=(Vec3& a, Vec3 b) {
    a.x -= b.x;
    a.y -= b.y;
    a.z -= b.z;
    return a;
}
MW_INLINE Vec3& operator*=(Vec3& a, Real s) {
    a.x *= s;
    a.y *= s;
    a.z *= s;
    return a;
}
// Component-wise product (a reflection's scale applied to a point or a velocity).
MW_INLINE Vec3 hadamard(Vec3 a, Vec3 b) { return {a.x * b.x, a.y * b.y, a.z * b.z}; }
MW_INLINE Real dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
MW_INLINE Vec3 cross(Vec3 a, Vec3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
MW_INLINE Real norm2(Vec3 a) { return dot(a, a); }
MW_INLINE Real norm(Vec3 a) { return std::sqrt(dot(a, a)); }
MW_INLINE bool is_finite(Vec3 a) { return std::isfinite(a.x) && std::isfinite(a.y) && std::isfinite(a.z); }

// Row-major 3x3 matrix.
struct Mat3 {
    Real m[3][3];
};

MW_INLINE Mat3 mat3_zero() { return Mat3{{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}}}; }
MW_INLINE Mat3 mat3_identity() { return Mat3{{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}; }
MW_INLINE Vec3 operator*(const Mat3& a, Vec3 v) {
    return {a.m[0][0] * v.x + a.m[0][1] * v.y + a.m[0][2] * v.z, a.m[1][0] * v.x + a.m[1][1] * v.y + a.m[1][2] * v.z,
            a.m[2][0] * v.x + a.m[2][1] * v.y + a.m[2][2] * v.z};
}
MW_INLINE Mat3 operator*(const Mat3& a, const Mat3& b) {
    Mat3 c = mat3_zero();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j)
            for (int k = 0; k < 3; ++k) c.m[i][j] += a.m[i][k] * b.m[k][j];
    return c;
}
MW_INLINE Mat3 operator+(const Mat3& a, const Mat3& b) {
    Mat3 c;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) c.m[i][j] = a.m[i][j] + b.m[i][j];
    return c;
}
MW_INLINE Mat3 operator*(Real s, const Mat3& a) {
    Mat3 c;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) c.m[i][j] = s * a.m[i][j];
    return c;
}
MW_INLINE Mat3 transpose(const Mat3& a) {
    Mat3 t;
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) t.m[i][j] = a.m[j][i];
    return t;
}
// a b^T
MW_INLINE Mat3 outer(Vec3 a, Vec3 b) {
    return Mat3{{{a.x * b.x, a.x * b.y, a.x * b.z}, {a.y * b.x, a.y * b.y, a.y * b.z}, {a.z * b.x, a.z * b.y, a.z * b.z}}};
}

}  // namespace mw
