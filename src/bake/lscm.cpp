#include "bake/lscm.h"

#include <cmath>

#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

namespace shadel {
namespace {

constexpr uint32_t kPinned = ~0u;

// Index of the vertex farthest from `from` (ties: lowest index, so the result is deterministic).
uint32_t farthestVertex(const std::vector<glm::dvec3>& positions, glm::dvec3 from) {
    uint32_t best = 0;
    double bestDistance = -1;
    for (uint32_t v = 0; v < positions.size(); ++v) {
        glm::dvec3 d = positions[v] - from;
        double distance = glm::dot(d, d);
        if (distance > bestDistance) bestDistance = distance, best = v;
    }
    return best;
}

} // namespace

bool lscmFlatten(const std::vector<glm::dvec3>& positions, const std::vector<uint32_t>& triangles,
                 std::vector<glm::dvec2>& uv) {
    uint32_t vertexCount = uint32_t(positions.size());
    uv.assign(vertexCount, glm::dvec2(0.0));
    if (vertexCount < 3 || triangles.size() < 3) return false;

    // Pin the ends of an approximate diameter (two farthest-point sweeps): pins far apart keep
    // the solve well conditioned and put the least distortion in the middle of the patch.
    uint32_t pinA = farthestVertex(positions, positions[0]);
    uint32_t pinB = farthestVertex(positions, positions[pinA]);
    double diameter = glm::length(positions[pinB] - positions[pinA]);
    if (pinA == pinB || !(diameter > 0)) return false;
    glm::dvec2 pinnedUv[2] = {glm::dvec2(0.0), glm::dvec2(diameter, 0.0)};

    // Unknowns (u, v) of every free vertex, interleaved so a vertex's two columns are adjacent.
    std::vector<uint32_t> column(vertexCount);
    uint32_t freeCount = 0;
    for (uint32_t v = 0; v < vertexCount; ++v)
        column[v] = (v == pinA || v == pinB) ? kPinned : 2 * freeCount++;
    auto pinnedValue = [&](uint32_t v) { return v == pinA ? pinnedUv[0] : pinnedUv[1]; };

    // Per triangle, with corners (x_j, y_j) in an orthonormal frame of its plane and
    // W_j = (x_{j+2} - x_{j+1}) + i (y_{j+2} - y_{j+1}), the map is conformal on the triangle when
    // sum_j W_j (u_j + i v_j) = 0. Dividing by sqrt(2 area) makes the squared residual the
    // triangle's conformal energy. Real part: sum a u - b v; imaginary part: sum b u + a v.
    size_t triangleCount = triangles.size() / 3;
    std::vector<Eigen::Triplet<double>> entries;
    entries.reserve(triangleCount * 12);
    Eigen::VectorXd rhs = Eigen::VectorXd::Zero(Eigen::Index(2 * triangleCount));
    for (size_t t = 0; t < triangleCount; ++t) {
        const uint32_t* idx = &triangles[3 * t];
        glm::dvec3 p0 = positions[idx[0]], p1 = positions[idx[1]], p2 = positions[idx[2]];
        glm::dvec3 normal = glm::cross(p1 - p0, p2 - p0);
        double doubleArea = glm::length(normal);
        if (!(doubleArea > 0)) return false;
        glm::dvec3 ex = glm::normalize(p1 - p0);
        glm::dvec3 ey = glm::cross(normal / doubleArea, ex);
        glm::dvec2 x[3] = {glm::dvec2(0.0), glm::dvec2(glm::dot(p1 - p0, ex), 0.0),
                           glm::dvec2(glm::dot(p2 - p0, ex), glm::dot(p2 - p0, ey))};
        double weight = 1.0 / std::sqrt(doubleArea);
        Eigen::Index realRow = Eigen::Index(2 * t), imagRow = realRow + 1;
        for (int j = 0; j < 3; ++j) {
            glm::dvec2 w = (x[(j + 2) % 3] - x[(j + 1) % 3]) * weight;
            double a = w.x, b = w.y;
            uint32_t v = idx[j];
            if (column[v] == kPinned) {
                glm::dvec2 q = pinnedValue(v);
                rhs[realRow] -= a * q.x - b * q.y;
                rhs[imagRow] -= b * q.x + a * q.y;
                continue;
            }
            Eigen::Index cu = Eigen::Index(column[v]), cv = cu + 1;
            entries.emplace_back(realRow, cu, a);
            entries.emplace_back(realRow, cv, -b);
            entries.emplace_back(imagRow, cu, b);
            entries.emplace_back(imagRow, cv, a);
        }
    }
    Eigen::SparseMatrix<double> system(Eigen::Index(2 * triangleCount),
                                       Eigen::Index(2 * freeCount));
    system.setFromTriplets(entries.begin(), entries.end());

    // Normal equations: symmetric positive definite once two vertices are pinned on a connected
    // patch, so a sparse Cholesky (AMD ordering) solves them in near-linear time on surface meshes.
    Eigen::SparseMatrix<double> normal = system.transpose() * system;
    Eigen::VectorXd normalRhs = system.transpose() * rhs;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(normal);
    if (solver.info() != Eigen::Success) return false;
    Eigen::VectorXd solution = solver.solve(normalRhs);
    if (solver.info() != Eigen::Success) return false;

    for (uint32_t v = 0; v < vertexCount; ++v) {
        if (column[v] == kPinned) {
            uv[v] = pinnedValue(v);
            continue;
        }
        uv[v] = glm::dvec2(solution[column[v]], solution[column[v] + 1]);
        if (!std::isfinite(uv[v].x) || !std::isfinite(uv[v].y)) return false;
    }
    return true;
}

} // namespace shadel
