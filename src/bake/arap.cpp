#include "bake/arap.h"

#include <algorithm>
#include <cmath>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace shadel {
namespace {

// Cotangents of nearly flat angles explode; clamping keeps the system well conditioned (the
// weights only set how much each edge counts).
constexpr double kMaxCotangent = 1e3;

} // namespace

bool arapRefine(const std::vector<glm::dvec3>& positions, const std::vector<uint32_t>& triangles,
                std::vector<glm::dvec2>& uv, int iterations) {
    size_t vertexCount = positions.size(), triangleCount = triangles.size() / 3;
    if (vertexCount < 3 || triangleCount == 0 || uv.size() != vertexCount) return false;

    // Each triangle in an orthonormal frame of its plane, and the cotangent of the angle opposite
    // each edge (edge e runs from corner e to corner e + 1).
    std::vector<glm::dvec2> rest(triangles.size());
    std::vector<double> cotangent(triangles.size());
    for (size_t t = 0; t < triangleCount; ++t) {
        const uint32_t* idx = &triangles[3 * t];
        glm::dvec3 p0 = positions[idx[0]], p1 = positions[idx[1]], p2 = positions[idx[2]];
        glm::dvec3 normal = glm::cross(p1 - p0, p2 - p0);
        double doubleArea = glm::length(normal);
        if (!(doubleArea > 0)) return false;
        glm::dvec3 ex = glm::normalize(p1 - p0), ey = glm::cross(normal / doubleArea, ex);
        rest[3 * t] = glm::dvec2(0.0);
        rest[3 * t + 1] = glm::dvec2(glm::dot(p1 - p0, ex), 0.0);
        rest[3 * t + 2] = glm::dvec2(glm::dot(p2 - p0, ex), glm::dot(p2 - p0, ey));
        for (int e = 0; e < 3; ++e) {
            glm::dvec2 a = rest[3 * t + (e + 2) % 3]; // corner opposite edge e
            glm::dvec2 u = rest[3 * t + e] - a, v = rest[3 * t + (e + 1) % 3] - a;
            double cross = std::abs(u.x * v.y - u.y * v.x);
            cotangent[3 * t + e] =
                std::clamp(glm::dot(u, v) / cross, -kMaxCotangent, kMaxCotangent);
        }
    }

    // Global step matrix: the cotangent Laplacian, vertex 0 pinned (removes the translation).
    auto column = [](uint32_t v) { return Eigen::Index(v) - 1; };
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(triangleCount * 12);
    for (size_t t = 0; t < triangleCount; ++t) {
        for (int e = 0; e < 3; ++e) {
            uint32_t i = triangles[3 * t + e], j = triangles[3 * t + (e + 1) % 3];
            double w = cotangent[3 * t + e];
            if (i != 0) entries.emplace_back(column(i), column(i), w);
            if (j != 0) entries.emplace_back(column(j), column(j), w);
            if (i != 0 && j != 0) {
                entries.emplace_back(column(i), column(j), -w);
                entries.emplace_back(column(j), column(i), -w);
            }
        }
    }
    Eigen::Index n = Eigen::Index(vertexCount) - 1;
    Eigen::SparseMatrix<double> laplacian(n, n);
    laplacian.setFromTriplets(entries.begin(), entries.end());
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(laplacian);
    if (solver.info() != Eigen::Success) return false;

    std::vector<glm::dvec2> current = uv;
    std::vector<glm::dmat2> rotation(triangleCount);
    Eigen::MatrixXd rhs(n, 2);
    for (int iteration = 0; iteration < iterations; ++iteration) {
        // Local step: the rotation closest to each triangle's current map (2x2 polar
        // decomposition: maximize trace(R^T S) over rotations R).
        for (size_t t = 0; t < triangleCount; ++t) {
            double s00 = 0, s01 = 0, s10 = 0, s11 = 0;
            for (int e = 0; e < 3; ++e) {
                uint32_t i = triangles[3 * t + e], j = triangles[3 * t + (e + 1) % 3];
                glm::dvec2 du = current[i] - current[j];
                glm::dvec2 dx = rest[3 * t + e] - rest[3 * t + (e + 1) % 3];
                double w = cotangent[3 * t + e];
                s00 += w * du.x * dx.x, s01 += w * du.x * dx.y;
                s10 += w * du.y * dx.x, s11 += w * du.y * dx.y;
            }
            double angle = std::atan2(s10 - s01, s00 + s11);
            double c = std::cos(angle), s = std::sin(angle);
            rotation[t] = glm::dmat2(c, s, -s, c); // columns: (c, s), (-s, c)
        }
        // Global step: positions whose edges best follow the rotated rest edges.
        rhs.setZero();
        for (size_t t = 0; t < triangleCount; ++t) {
            for (int e = 0; e < 3; ++e) {
                uint32_t i = triangles[3 * t + e], j = triangles[3 * t + (e + 1) % 3];
                glm::dvec2 edge = cotangent[3 * t + e] *
                                  (rotation[t] * (rest[3 * t + e] - rest[3 * t + (e + 1) % 3]));
                if (i != 0) rhs(column(i), 0) += edge.x, rhs(column(i), 1) += edge.y;
                if (j != 0) rhs(column(j), 0) -= edge.x, rhs(column(j), 1) -= edge.y;
            }
        }
        // Vertex 0 stays where it is: its edges move to the right-hand side.
        for (size_t t = 0; t < triangleCount; ++t)
            for (int e = 0; e < 3; ++e) {
                uint32_t i = triangles[3 * t + e], j = triangles[3 * t + (e + 1) % 3];
                double w = cotangent[3 * t + e];
                if (i == 0 && j != 0)
                    rhs(column(j), 0) += w * current[0].x, rhs(column(j), 1) += w * current[0].y;
                if (j == 0 && i != 0)
                    rhs(column(i), 0) += w * current[0].x, rhs(column(i), 1) += w * current[0].y;
            }
        Eigen::MatrixXd solution = solver.solve(rhs);
        if (solver.info() != Eigen::Success || !solution.allFinite()) return false;
        for (uint32_t v = 1; v < vertexCount; ++v)
            current[v] = glm::dvec2(solution(column(v), 0), solution(column(v), 1));
    }
    uv = std::move(current);
    return true;
}

} // namespace shadel
