#include <gtest/gtest.h>

#include "core/host.h"

using namespace shadel;

TEST(Host, CpuModelIsTheFirstModelNameLine) {
    const char* x86 = "processor\t: 0\nvendor_id\t: AuthenticAMD\nmodel name\t: AMD EPYC 7B13  \n"
                      "flags\t\t: fpu avx2\n\nprocessor\t: 1\nmodel name\t: AMD EPYC 7B13\n";
    EXPECT_EQ(cpuModelFromCpuinfo(x86), "AMD EPYC 7B13");
}

TEST(Host, OtherKernelsKeysAndMissingValuesAreHandled) {
    EXPECT_EQ(cpuModelFromCpuinfo("Processor\t: ARMv7 Processor rev 4 (v7l)\nBogoMIPS\t: 38.40\n"),
              "ARMv7 Processor rev 4 (v7l)");
    EXPECT_EQ(cpuModelFromCpuinfo("system type\t: MT7621\ncpu model\t: MIPS 1004Kc V2.15\n"),
              "MIPS 1004Kc V2.15");
    // A key with an empty value, a value without a key, no final newline, nothing at all.
    EXPECT_EQ(cpuModelFromCpuinfo("model name\t:   \nmodel name: Second"), "Second");
    EXPECT_EQ(cpuModelFromCpuinfo("processor : 0\nvendor_id : X\n"), "unknown");
    EXPECT_EQ(cpuModelFromCpuinfo(""), "unknown");
    EXPECT_EQ(cpuModelFromCpuinfo("model names: not the key\n"), "unknown");
}

TEST(Host, ThisMachineHasACpuName) {
    HostInfo h = hostInfo();
    EXPECT_FALSE(h.cpu.empty());
#if defined(__linux__) && (defined(__x86_64__) || defined(__i386__))
    EXPECT_NE(h.cpu, "unknown"); // x86 Linux kernels list a model name
    EXPECT_GT(h.threads, 0u);
#endif
}
