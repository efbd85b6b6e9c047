#pragma once
// Errors that reach the user: one line naming the input and the reason, exit code 2.
#include <stdexcept>
#include <string>

namespace shadel {

// Thrown for bad user input (files, flags, scenes). The app prints what() on one line
// and exits with code 2.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// Thrown when the device lacks something we need, or Vulkan fails in a way we cannot recover.
struct DeviceError : std::runtime_error {
    using std::runtime_error::runtime_error;
};

} // namespace shadel
