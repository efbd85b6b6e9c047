// `shadel info`: the Vulkan devices, the one --device selects, and the bake cache folder.
#include <cstdio>

#include "app/commands.h"
#include "app/subcommands.h"

namespace shadel {

Subcommand addInfoCommand(CLI::App& app) {
    CLI::App* c = app.add_subcommand("info", "print the device, driver, features and limits");
    return {c, [](const GlobalFlags& g) {
                std::printf("Vulkan devices:\n%s", listPhysicalDevices().c_str());
                std::printf("cache folder: %s\n", defaultCacheFolder().c_str());
                GpuGuard device(g);
                std::printf("selected (--device %s):\n%s", g.device.c_str(),
                            describeDevice(device.gpu.device).c_str());
                return 0;
            }};
}

} // namespace shadel
