#pragma once
// The machine a run measured on. On a software device (lavapipe) every timing is the host CPU's,
// and the same build's ratios differ from one CPU to another (docs/lighting/README.md), so a
// figure is only comparable with the CPU beside it: render stats and bench JSON record it.
#include <string>
#include <string_view>

namespace shadel {

struct HostInfo {
    std::string cpu;      // the CPU's model name, "unknown" where the system does not say
    unsigned threads = 0; // hardware threads the process may use (0: unknown)
};

HostInfo hostInfo();

// The model name in /proc/cpuinfo's text: the first "model name" (x86) or "Processor" /
// "cpu model" line (some ARM and MIPS kernels), trimmed; "unknown" when none has a value.
std::string cpuModelFromCpuinfo(std::string_view cpuinfo);

} // namespace shadel
