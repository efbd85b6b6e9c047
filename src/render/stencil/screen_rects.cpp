#include "render/stencil/screen_rects.h"

#include <algorithm>
#include <cmath>

namespace shadel {

PixelRect projectedBoxRect(const glm::mat4& viewProj, glm::vec3 lo, glm::vec3 hi, int width,
                           int height, int margin) {
    const PixelRect whole{0, 0, width, height};
    glm::vec2 pmin(1e30f), pmax(-1e30f);
    int behind = 0;
    for (int c = 0; c < 8; ++c) {
        glm::vec3 p((c & 1) ? hi.x : lo.x, (c & 2) ? hi.y : lo.y, (c & 4) ? hi.z : lo.z);
        glm::vec4 clip = viewProj * glm::vec4(p, 1.0f);
        if (clip.w <= 1e-4f) {
            ++behind;
            continue;
        }
        glm::vec2 px = (glm::vec2(clip) / clip.w * 0.5f + 0.5f) * glm::vec2(width, height);
        pmin = glm::min(pmin, px);
        pmax = glm::max(pmax, px);
    }
    if (behind == 8) return {}; // nothing of it is in front of the camera
    // A box across the camera plane projects unboundedly: the whole target (conservative).
    if (behind > 0 || !std::isfinite(pmin.x + pmin.y + pmax.x + pmax.y)) return whole;
    // Clamp in float before converting: a far-off-screen corner may not fit an int.
    auto clampTo = [](float v, int limit) { return std::clamp(v, -1.0f, float(limit) + 1.0f); };
    PixelRect r{int(std::floor(clampTo(pmin.x, width))) - margin,
                int(std::floor(clampTo(pmin.y, height))) - margin,
                int(std::ceil(clampTo(pmax.x, width))) + margin,
                int(std::ceil(clampTo(pmax.y, height))) + margin};
    r = {std::clamp(r.x0, 0, width), std::clamp(r.y0, 0, height), std::clamp(r.x1, 0, width),
         std::clamp(r.y1, 0, height)};
    return r.empty() ? PixelRect{} : r;
}

std::vector<PixelRect> disjointCover(std::span<const PixelRect> rects) {
    std::vector<int> ys;
    for (const PixelRect& r : rects)
        if (!r.empty()) ys.insert(ys.end(), {r.y0, r.y1});
    std::sort(ys.begin(), ys.end());
    ys.erase(std::unique(ys.begin(), ys.end()), ys.end());
    std::vector<PixelRect> done, open; // open: rects that reach the band being built
    std::vector<std::pair<int, int>> spans;
    for (size_t b = 0; b + 1 < ys.size(); ++b) {
        int y0 = ys[b], y1 = ys[b + 1];
        spans.clear();
        for (const PixelRect& r : rects)
            if (!r.empty() && r.y0 <= y0 && r.y1 >= y1) spans.push_back({r.x0, r.x1});
        std::sort(spans.begin(), spans.end());
        std::vector<std::pair<int, int>> merged;
        for (auto [a, c] : spans) {
            if (!merged.empty() && a <= merged.back().second)
                merged.back().second = std::max(merged.back().second, c);
            else
                merged.push_back({a, c});
        }
        std::vector<PixelRect> next;
        for (auto [a, c] : merged) {
            auto same = std::find_if(open.begin(), open.end(), [&](const PixelRect& o) {
                return o.x0 == a && o.x1 == c && o.y1 == y0;
            });
            if (same != open.end()) {
                same->y1 = y1;
                next.push_back(*same);
                open.erase(same);
            } else {
                next.push_back({a, y0, c, y1});
            }
        }
        done.insert(done.end(), open.begin(), open.end()); // spans that stop here
        open = std::move(next);
    }
    done.insert(done.end(), open.begin(), open.end());
    return done;
}

} // namespace shadel
