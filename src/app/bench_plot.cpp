#include "app/bench_plot.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <imgui.h>

#include "app/output_files.h"
#include "core/log.h"

namespace shadel {

const uint8_t kPlotModeColours[3][3] = {{70, 130, 220}, {230, 120, 40}, {60, 170, 90}};

namespace {

const char* const kModes[3] = {"forward", "decoupled", "reuse"};

// Text from ImGui's default font (ProggyClean, 13 px), alpha-blended in `colour`.
struct TextPainter {
    ImFontAtlas atlas;
    ImFont* font = nullptr;
    unsigned char* pixels = nullptr;
    int atlasW = 0, atlasH = 0;
    TextPainter() {
        font = atlas.AddFontDefault();
        atlas.GetTexDataAsAlpha8(&pixels, &atlasW, &atlasH);
    }
    int width(const std::string& text) const {
        float w = 0;
        for (char c : text)
            if (const ImFontGlyph* g = font->FindGlyph(ImWchar(c))) w += g->AdvanceX;
        return int(w);
    }
    // Draws at (x, y) = top left; vertical: rotated 90 degrees counter-clockwise (reads upward).
    void draw(PlotImage& img, int x, int y, const std::string& text, const uint8_t colour[3],
              bool vertical = false) const {
        float pen = 0;
        for (char c : text) {
            const ImFontGlyph* g = font->FindGlyph(ImWchar(c));
            if (!g) continue;
            int gw = int(std::lround((g->U1 - g->U0) * atlasW));
            int gh = int(std::lround((g->V1 - g->V0) * atlasH));
            int u0 = int(std::lround(g->U0 * atlasW)), v0 = int(std::lround(g->V0 * atlasH));
            for (int gy = 0; gy < gh; ++gy)
                for (int gx = 0; gx < gw; ++gx) {
                    float a = pixels[(v0 + gy) * atlasW + u0 + gx] / 255.0f;
                    if (a <= 0.0f) continue;
                    int lx = int(pen + g->X0) + gx, ly = int(g->Y0) + gy;
                    int px = vertical ? x + ly : x + lx, py = vertical ? y - lx : y + ly;
                    if (px < 0 || py < 0 || px >= int(img.width) || py >= int(img.height)) continue;
                    uint8_t* p = &img.rgba[(size_t(py) * img.width + px) * 4];
                    for (int k = 0; k < 3; ++k)
                        p[k] = uint8_t(std::lround(p[k] * (1 - a) + colour[k] * a));
                }
            pen += g->AdvanceX;
        }
    }
};

void fillRect(PlotImage& img, int x0, int y0, int x1, int y1, const uint8_t c[3]) {
    for (int y = std::max(y0, 0); y < std::min(y1, int(img.height)); ++y)
        for (int x = std::max(x0, 0); x < std::min(x1, int(img.width)); ++x) {
            uint8_t* p = &img.rgba[(size_t(y) * img.width + x) * 4];
            p[0] = c[0], p[1] = c[1], p[2] = c[2], p[3] = 255;
        }
}

} // namespace

PlotImage plotBench(const nlohmann::json& bench) {
    // Passes in first-seen order over the modes; ms per mode (0 when a mode lacks the pass).
    std::vector<std::string> passes;
    for (const char* m : kModes)
        for (const auto& p : bench["modes"][m]["passes"]) {
            std::string name = p["name"];
            if (std::find(passes.begin(), passes.end(), name) == passes.end())
                passes.push_back(name);
        }
    std::vector<std::array<double, 3>> ms(passes.size(), {0, 0, 0});
    double most = 1e-6;
    for (int m = 0; m < 3; ++m)
        for (const auto& p : bench["modes"][kModes[m]]["passes"]) {
            size_t i = std::find(passes.begin(), passes.end(), p["name"].get<std::string>()) -
                       passes.begin();
            ms[i][m] = p["gpu_ms"].get<double>();
            most = std::max(most, ms[i][m]);
        }

    TextPainter text;
    const int group = 36, bar = 10, left = 60, top = 40, plotH = 260, bottom = 130;
    PlotImage img;
    img.width = uint32_t(left + std::max<size_t>(passes.size(), 1) * group + 20);
    img.width = std::max(img.width, 420u);
    std::string title = format("shadel bench: %s, %s, GPU ms per pass (median)",
                               bench.value("scene", std::string("?")).c_str(),
                               bench.value("device", std::string("?")).c_str());
    img.width = std::max(img.width, uint32_t(text.width(title) + 16));
    img.height = uint32_t(top + plotH + bottom);
    img.rgba.assign(size_t(img.width) * img.height * 4, 255);
    const uint8_t ink[3] = {30, 30, 30}, grid[3] = {225, 225, 225};
    text.draw(img, 8, 8, title, ink);
    for (int m = 0; m < 3; ++m) { // legend
        int x = 8 + m * 110;
        fillRect(img, x, 24, x + 10, 34, kPlotModeColours[m]);
        text.draw(img, x + 14, 22, kModes[m], ink);
    }
    int baseY = top + plotH;
    for (int t = 0; t <= 4; ++t) { // grid lines and axis values
        int y = baseY - plotH * t / 4;
        fillRect(img, left, y, int(img.width) - 10, y + 1, t == 0 ? ink : grid);
        text.draw(img, 4, y - 7, format("%.1f", most * t / 4), ink);
    }
    for (size_t i = 0; i < passes.size(); ++i) {
        int x = left + int(i) * group + 3;
        for (int m = 0; m < 3; ++m) {
            int h = int(std::lround(ms[i][m] / most * plotH));
            if (h > 0)
                fillRect(img, x + m * bar, baseY - h, x + (m + 1) * bar, baseY,
                         kPlotModeColours[m]);
        }
        text.draw(img, x + 8, baseY + 6 + text.width(passes[i]), passes[i], ink, true);
    }
    return img;
}

void writeBenchPlot(const nlohmann::json& bench, const std::string& path) {
    PlotImage img = plotBench(bench);
    std::vector<uint8_t> png = encodePngRgb(img.rgba, img.width, img.height);
    writeOutputFile(path, png.data(), png.size());
}

} // namespace shadel
