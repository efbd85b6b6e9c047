#include "render/debug/inspect.h"

#include <map>

#include "common/print_labels.h"

namespace shadel {

InspectedPixel frontFragment(const std::vector<ShaderPrint>& prints) {
    std::map<uint32_t, float> depthByTag;
    for (const ShaderPrint& p : prints)
        if (p.label == PRINT_FRAGMENT_DEPTH) {
            auto [it, fresh] = depthByTag.emplace(p.tag, p.f(0));
            if (!fresh) it->second = std::max(it->second, p.f(0));
        }
    InspectedPixel out;
    out.fragments = uint32_t(depthByTag.size());
    if (depthByTag.empty()) { // prints without fragments (compute passes): keep them all
        out.prints = prints;
        return out;
    }
    uint32_t front = depthByTag.begin()->first;
    for (auto [tag, depth] : depthByTag)
        if (depth > depthByTag[front]) front = tag;
    for (const ShaderPrint& p : prints)
        if (p.tag == front) out.prints.push_back(p);
    return out;
}

} // namespace shadel
