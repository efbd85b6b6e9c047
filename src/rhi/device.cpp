#include "rhi/device.h"

#include <cstdlib>
#include <cstring>
#include <dlfcn.h>
#include <optional>
#include <vector>

#include "core/log.h"

namespace shadel {

const char* vkResultName(VkResult r) {
    switch (r) {
#define CASE(x)                                                                                    \
    case x:                                                                                        \
        return #x;
        CASE(VK_SUCCESS)
        CASE(VK_NOT_READY)
        CASE(VK_TIMEOUT)
        CASE(VK_INCOMPLETE)
        CASE(VK_ERROR_OUT_OF_HOST_MEMORY)
        CASE(VK_ERROR_OUT_OF_DEVICE_MEMORY)
        CASE(VK_ERROR_INITIALIZATION_FAILED)
        CASE(VK_ERROR_DEVICE_LOST)
        CASE(VK_ERROR_MEMORY_MAP_FAILED)
        CASE(VK_ERROR_LAYER_NOT_PRESENT)
        CASE(VK_ERROR_EXTENSION_NOT_PRESENT)
        CASE(VK_ERROR_FEATURE_NOT_PRESENT)
        CASE(VK_ERROR_INCOMPATIBLE_DRIVER)
        CASE(VK_ERROR_TOO_MANY_OBJECTS)
        CASE(VK_ERROR_FORMAT_NOT_SUPPORTED)
        CASE(VK_ERROR_FRAGMENTED_POOL)
        CASE(VK_ERROR_OUT_OF_POOL_MEMORY)
#undef CASE
    default:
        return "VK_ERROR_(unknown)";
    }
}

void throwVkError(VkResult r, const char* call, const char* file, int line) {
    throw DeviceError(
        format("Vulkan call failed: %s returned %s (%s:%d)", call, vkResultName(r), file, line));
}

static VKAPI_ATTR VkBool32 VKAPI_CALL
debugCallback(VkDebugUtilsMessageSeverityFlagBitsEXT severity, VkDebugUtilsMessageTypeFlagsEXT,
              const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    Device& device = *static_cast<Device*>(user);
    if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
        device.validationErrors++;
        if (device.printValidation) SHADEL_ERROR("vulkan validation: %s", data->pMessage);
    } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
        device.validationWarnings++;
        if (device.printValidation) SHADEL_WARN("vulkan validation: %s", data->pMessage);
    }
    return VK_FALSE;
}

static bool hasLayer(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceLayerProperties(&n, nullptr);
    std::vector<VkLayerProperties> layers(n);
    vkEnumerateInstanceLayerProperties(&n, layers.data());
    for (auto& l : layers)
        if (!std::strcmp(l.layerName, name)) return true;
    return false;
}

static bool hasInstanceExtension(const char* name) {
    uint32_t n = 0;
    vkEnumerateInstanceExtensionProperties(nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateInstanceExtensionProperties(nullptr, &n, exts.data());
    for (auto& e : exts)
        if (!std::strcmp(e.extensionName, name)) return true;
    return false;
}

static std::vector<VkExtensionProperties> deviceExtensions(VkPhysicalDevice pd) {
    uint32_t n = 0;
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, nullptr);
    std::vector<VkExtensionProperties> exts(n);
    vkEnumerateDeviceExtensionProperties(pd, nullptr, &n, exts.data());
    return exts;
}

static bool hasExtension(const std::vector<VkExtensionProperties>& exts, const char* name) {
    for (auto& e : exts)
        if (!std::strcmp(e.extensionName, name)) return true;
    return false;
}

static const char* typeName(VkPhysicalDeviceType t) {
    switch (t) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
        return "discrete GPU";
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
        return "integrated GPU";
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
        return "virtual GPU";
    case VK_PHYSICAL_DEVICE_TYPE_CPU:
        return "CPU";
    default:
        return "other";
    }
}

static VkInstance createInstanceForQuery() {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.apiVersion = VK_API_VERSION_1_3;
    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    VkInstance instance = VK_NULL_HANDLE;
    if (vkCreateInstance(&ci, nullptr, &instance) != VK_SUCCESS) return VK_NULL_HANDLE;
    return instance;
}

static std::vector<VkPhysicalDevice> physicalDevices(VkInstance instance) {
    uint32_t n = 0;
    vkEnumeratePhysicalDevices(instance, &n, nullptr);
    std::vector<VkPhysicalDevice> pds(n);
    vkEnumeratePhysicalDevices(instance, &n, pds.data());
    return pds;
}

std::string listPhysicalDevices() {
    VkInstance instance = createInstanceForQuery();
    if (!instance) return "  (no Vulkan instance)\n";
    std::string out;
    auto pds = physicalDevices(instance);
    for (size_t i = 0; i < pds.size(); ++i) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pds[i], &p);
        out += format("  [%zu] %s (%s)\n", i, p.deviceName, typeName(p.deviceType));
    }
    vkDestroyInstance(instance, nullptr);
    return out;
}

// Checks every feature the platform section of docs/design.md requires; returns the name of the
// first one missing.
struct FeatureChain {
    VkPhysicalDeviceFeatures2 core{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    VkPhysicalDeviceVulkan11Features v11{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_1_FEATURES};
    VkPhysicalDeviceVulkan12Features v12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    VkPhysicalDeviceVulkan13Features v13{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_3_FEATURES};
    void link() {
        core.pNext = &v11;
        v11.pNext = &v12;
        v12.pNext = &v13;
        v13.pNext = nullptr;
    }
};

static std::optional<std::string> missingRequiredFeature(VkPhysicalDevice pd) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(pd, &props);
    if (props.apiVersion < VK_API_VERSION_1_3) return std::string("Vulkan 1.3");
    FeatureChain f;
    f.link();
    vkGetPhysicalDeviceFeatures2(pd, &f.core);
    struct Req {
        VkBool32 have;
        const char* name;
    };
    const Req reqs[] = {
        {f.v13.dynamicRendering, "dynamicRendering"},
        {f.v13.synchronization2, "synchronization2"},
        {f.v12.timelineSemaphore, "timelineSemaphore"},
        {f.v12.descriptorIndexing, "descriptorIndexing"},
        {f.v12.runtimeDescriptorArray, "runtimeDescriptorArray"},
        {f.v12.descriptorBindingPartiallyBound, "descriptorBindingPartiallyBound"},
        {f.v12.shaderSampledImageArrayNonUniformIndexing,
         "shaderSampledImageArrayNonUniformIndexing"},
        {f.v12.shaderStorageImageArrayNonUniformIndexing,
         "shaderStorageImageArrayNonUniformIndexing"},
        {f.v12.descriptorBindingSampledImageUpdateAfterBind,
         "descriptorBindingSampledImageUpdateAfterBind"},
        {f.v12.descriptorBindingStorageImageUpdateAfterBind,
         "descriptorBindingStorageImageUpdateAfterBind"},
        {f.v12.bufferDeviceAddress, "bufferDeviceAddress"},
        {f.v12.shaderBufferInt64Atomics, "shaderBufferInt64Atomics"},
        {f.v12.drawIndirectCount, "drawIndirectCount"},
        {f.v12.scalarBlockLayout, "scalarBlockLayout"},
        {f.v12.hostQueryReset, "hostQueryReset"},
        {f.v11.shaderDrawParameters, "shaderDrawParameters"},
        {f.core.features.shaderInt64, "shaderInt64"},
        {f.core.features.fragmentStoresAndAtomics, "fragmentStoresAndAtomics"},
        {f.core.features.multiDrawIndirect, "multiDrawIndirect"},
        {f.core.features.drawIndirectFirstInstance, "drawIndirectFirstInstance"},
        {f.core.features.samplerAnisotropy, "samplerAnisotropy"},
        {f.core.features.shaderStorageImageWriteWithoutFormat,
         "shaderStorageImageWriteWithoutFormat"},
        {f.core.features.depthClamp, "depthClamp"},
    };
    for (const Req& r : reqs)
        if (!r.have) return std::string(r.name);
    if (!props.limits.timestampComputeAndGraphics)
        return std::string("timestampComputeAndGraphics");
    // Subgroup operations in compute and fragment shaders: the shadel passes reduce over
    // subgroups, and forward pixels cull few lights per subgroup (light_cull.glsl).
    VkPhysicalDeviceSubgroupProperties subgroup{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SUBGROUP_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &subgroup};
    vkGetPhysicalDeviceProperties2(pd, &props2);
    const VkShaderStageFlags stages = VK_SHADER_STAGE_COMPUTE_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;
    const VkSubgroupFeatureFlags ops =
        VK_SUBGROUP_FEATURE_BASIC_BIT | VK_SUBGROUP_FEATURE_VOTE_BIT |
        VK_SUBGROUP_FEATURE_ARITHMETIC_BIT | VK_SUBGROUP_FEATURE_BALLOT_BIT;
    if ((subgroup.supportedStages & stages) != stages)
        return std::string("subgroup operations in compute and fragment shaders");
    if ((subgroup.supportedOperations & ops) != ops)
        return std::string("subgroup basic, vote, arithmetic and ballot operations");
    return std::nullopt;
}

// RenderDoc's capture layer offers Vulkan 1.3 (and buffer device addresses, which shadel's
// shaders read everything through) only on devices with bufferDeviceAddressCaptureReplay, so a
// device without it (lavapipe among them) shows up as Vulkan 1.2 under RenderDoc. Its library
// is loaded into the process when the layer is active.
static std::string renderDocHint() {
    void* renderDoc = dlopen("librenderdoc.so", RTLD_NOW | RTLD_NOLOAD);
    if (!renderDoc) return "";
    dlclose(renderDoc);
    return " (under RenderDoc, which offers Vulkan 1.3 only on devices with "
           "bufferDeviceAddressCaptureReplay: capture on a GPU whose driver has it)";
}

static VkPhysicalDevice choosePhysicalDevice(VkInstance instance, const std::string& selection) {
    auto pds = physicalDevices(instance);
    if (pds.empty())
        throw DeviceError("no Vulkan device found (is mesa-vulkan-drivers installed?)");
    auto isCpu = [](VkPhysicalDevice pd) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pd, &p);
        return p.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    };
    auto rank = [](VkPhysicalDevice pd) {
        VkPhysicalDeviceProperties p;
        vkGetPhysicalDeviceProperties(pd, &p);
        switch (p.deviceType) {
        case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU:
            return 4;
        case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU:
            return 3;
        case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU:
            return 2;
        case VK_PHYSICAL_DEVICE_TYPE_CPU:
            return 1;
        default:
            return 0;
        }
    };
    if (!selection.empty() && std::isdigit(uint8_t(selection[0]))) {
        char* end = nullptr;
        unsigned long index = std::strtoul(selection.c_str(), &end, 10);
        if (*end || index >= pds.size())
            throw InputError(format("--device %s: no such device index (devices:\n%s)",
                                    selection.c_str(), listPhysicalDevices().c_str()));
        if (auto missing = missingRequiredFeature(pds[index]))
            throw DeviceError(format("--device %s lacks required Vulkan feature %s%s",
                                     selection.c_str(), missing->c_str(), renderDocHint().c_str()));
        return pds[index];
    }
    if (selection != "auto" && selection != "cpu" && selection != "gpu")
        throw InputError(
            format("--device %s: expected auto, cpu, gpu or an index", selection.c_str()));
    VkPhysicalDevice best = VK_NULL_HANDLE;
    int bestRank = -1;
    std::string lastMissing;
    for (VkPhysicalDevice pd : pds) {
        if (selection == "cpu" && !isCpu(pd)) continue;
        if (selection == "gpu" && isCpu(pd)) continue;
        if (auto missing = missingRequiredFeature(pd)) {
            VkPhysicalDeviceProperties p;
            vkGetPhysicalDeviceProperties(pd, &p);
            lastMissing =
                format("%s lacks required Vulkan feature %s", p.deviceName, missing->c_str());
            SHADEL_DEBUG("skipping device: %s", lastMissing.c_str());
            continue;
        }
        if (rank(pd) > bestRank) best = pd, bestRank = rank(pd);
    }
    if (!best) {
        if (!lastMissing.empty()) throw DeviceError(lastMissing + renderDocHint());
        throw DeviceError(format("--device %s: no matching Vulkan device", selection.c_str()));
    }
    return best;
}

namespace {

// The instance (Vulkan 1.3; the validation layer and its messenger when asked), and the debug
// utils entry points that name objects and passes.
void createInstance(Device& device, const DeviceDesc& desc) {
    device.printValidation = desc.printValidation;
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "shadel";
    app.pEngineName = "shadel";
    app.apiVersion = VK_API_VERSION_1_3;

    std::vector<const char*> layers;
    std::vector<const char*> extensions;
    bool debugUtils = hasInstanceExtension(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    for (const std::string& e : desc.instanceExtensions) {
        if (!hasInstanceExtension(e.c_str()))
            throw DeviceError(format("the window needs instance extension %s", e.c_str()));
        extensions.push_back(e.c_str());
    }
    if (desc.validation) {
        if (!hasLayer("VK_LAYER_KHRONOS_validation"))
            throw DeviceError("validation requested but VK_LAYER_KHRONOS_validation is not "
                              "installed (apt-get install vulkan-validationlayers)");
        layers.push_back("VK_LAYER_KHRONOS_validation");
        device.validation = true;
    }
    VkDebugUtilsMessengerCreateInfoEXT messengerInfo{
        VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messengerInfo.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                                    VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
    messengerInfo.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    messengerInfo.pfnUserCallback = debugCallback;
    messengerInfo.pUserData = &device;

    VkInstanceCreateInfo ci{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ci.pApplicationInfo = &app;
    ci.enabledLayerCount = uint32_t(layers.size());
    ci.ppEnabledLayerNames = layers.data();
    ci.enabledExtensionCount = uint32_t(extensions.size());
    ci.ppEnabledExtensionNames = extensions.data();
    if (desc.validation && debugUtils) ci.pNext = &messengerInfo;
    VkResult r = vkCreateInstance(&ci, nullptr, &device.instance);
    if (r != VK_SUCCESS)
        throw DeviceError(format("cannot create a Vulkan 1.3 instance (%s)", vkResultName(r)));

    if (debugUtils) {
        device.setObjectName = (PFN_vkSetDebugUtilsObjectNameEXT)vkGetInstanceProcAddr(
            device.instance, "vkSetDebugUtilsObjectNameEXT");
        device.cmdBeginLabel = (PFN_vkCmdBeginDebugUtilsLabelEXT)vkGetInstanceProcAddr(
            device.instance, "vkCmdBeginDebugUtilsLabelEXT");
        device.cmdEndLabel = (PFN_vkCmdEndDebugUtilsLabelEXT)vkGetInstanceProcAddr(
            device.instance, "vkCmdEndDebugUtilsLabelEXT");
        if (desc.validation) {
            auto create = (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(
                device.instance, "vkCreateDebugUtilsMessengerEXT");
            if (create)
                VK_CHECK(create(device.instance, &messengerInfo, nullptr, &device.messenger));
        }
    }
}

// The physical device's properties, driver and the one queue family the engine uses (graphics,
// compute, timestamps); returns every family's properties.
std::vector<VkQueueFamilyProperties> describePhysicalDevice(Device& device,
                                                            const DeviceDesc& desc) {
    device.physical = choosePhysicalDevice(device.instance, desc.selection);
    vkGetPhysicalDeviceProperties(device.physical, &device.properties);
    vkGetPhysicalDeviceMemoryProperties(device.physical, &device.memory);
    device.name = device.properties.deviceName;
    device.isCpu = device.properties.deviceType == VK_PHYSICAL_DEVICE_TYPE_CPU;
    device.timestampPeriodNs = device.properties.limits.timestampPeriod;

    VkPhysicalDeviceDriverProperties driverProps{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
    VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    props2.pNext = &driverProps;
    vkGetPhysicalDeviceProperties2(device.physical, &props2);
    device.driver = format("%s %s", driverProps.driverName, driverProps.driverInfo);

    uint32_t familyCount = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(device.physical, &familyCount, nullptr);
    std::vector<VkQueueFamilyProperties> families(familyCount);
    vkGetPhysicalDeviceQueueFamilyProperties(device.physical, &familyCount, families.data());
    device.queueFamily = ~0u;
    for (uint32_t i = 0; i < familyCount; ++i) {
        if ((families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) &&
            (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) && families[i].timestampValidBits) {
            device.queueFamily = i;
            break;
        }
    }
    if (device.queueFamily == ~0u)
        throw DeviceError(
            format("%s has no graphics+compute queue with timestamps", device.name.c_str()));

    return families;
}

// Exactly what the engine requires, plus optional core features when present (sparse
// residency among them).
void requiredFeatures(Device& device, const std::vector<VkQueueFamilyProperties>& families,
                      FeatureChain& enable) {
    // Enable exactly what we require, plus optional features when present.
    FeatureChain f;
    f.link();
    vkGetPhysicalDeviceFeatures2(device.physical, &f.core);
    enable.link();
    enable.v13.dynamicRendering = VK_TRUE;
    enable.v13.synchronization2 = VK_TRUE;
    enable.v13.maintenance4 = f.v13.maintenance4;
    enable.v12.timelineSemaphore = VK_TRUE;
    enable.v12.descriptorIndexing = VK_TRUE;
    enable.v12.runtimeDescriptorArray = VK_TRUE;
    enable.v12.descriptorBindingPartiallyBound = VK_TRUE;
    enable.v12.shaderSampledImageArrayNonUniformIndexing = VK_TRUE;
    enable.v12.shaderStorageImageArrayNonUniformIndexing = VK_TRUE;
    enable.v12.descriptorBindingSampledImageUpdateAfterBind = VK_TRUE;
    enable.v12.descriptorBindingStorageImageUpdateAfterBind = VK_TRUE;
    enable.v12.descriptorBindingUpdateUnusedWhilePending =
        f.v12.descriptorBindingUpdateUnusedWhilePending;
    enable.v12.bufferDeviceAddress = VK_TRUE;
    enable.v12.shaderBufferInt64Atomics = VK_TRUE;
    enable.v12.drawIndirectCount = VK_TRUE;
    enable.v12.scalarBlockLayout = VK_TRUE;
    enable.v12.hostQueryReset = VK_TRUE;
    enable.v12.shaderFloat16 = f.v12.shaderFloat16;
    enable.v12.storageBuffer8BitAccess = f.v12.storageBuffer8BitAccess;
    enable.v12.shaderInt8 = f.v12.shaderInt8;
    enable.v11.shaderDrawParameters = VK_TRUE;
    enable.v11.storageBuffer16BitAccess = f.v11.storageBuffer16BitAccess;
    enable.core.features.shaderInt64 = VK_TRUE;
    enable.core.features.shaderInt16 = f.core.features.shaderInt16;
    enable.core.features.fragmentStoresAndAtomics = VK_TRUE;
    enable.core.features.vertexPipelineStoresAndAtomics =
        f.core.features.vertexPipelineStoresAndAtomics;
    enable.core.features.multiDrawIndirect = VK_TRUE;
    enable.core.features.drawIndirectFirstInstance = VK_TRUE;
    enable.core.features.samplerAnisotropy = VK_TRUE;
    enable.core.features.shaderStorageImageWriteWithoutFormat = VK_TRUE;
    enable.core.features.shaderStorageImageReadWithoutFormat =
        f.core.features.shaderStorageImageReadWithoutFormat;
    enable.core.features.depthClamp = VK_TRUE;
    enable.core.features.independentBlend = f.core.features.independentBlend;
    // Block-compressed textures (texture streaming). SHADEL_DISABLE_BC=1 leaves them off, as on
    // a device without them (tests of the RGBA8 fallback).
    const char* noBc = std::getenv("SHADEL_DISABLE_BC");
    if ((!noBc || std::strcmp(noBc, "1") != 0) && f.core.features.textureCompressionBC) {
        enable.core.features.textureCompressionBC = VK_TRUE;
        device.optional.textureCompressionBC = true;
    }
    // Sparse residency (texture streaming, --streaming sparse). SHADEL_DISABLE_SPARSE=1 leaves
    // it off, as on a device without it (tests of that error path).
    const char* noSparse = std::getenv("SHADEL_DISABLE_SPARSE");
    if ((!noSparse || std::strcmp(noSparse, "1") != 0) && f.core.features.sparseBinding &&
        f.core.features.sparseResidencyImage2D &&
        (families[device.queueFamily].queueFlags & VK_QUEUE_SPARSE_BINDING_BIT)) {
        enable.core.features.sparseBinding = VK_TRUE;
        enable.core.features.sparseResidencyImage2D = VK_TRUE;
        device.optional.sparseResidency = true;
    }
}

// Optional device extensions the device has (mesh shaders, ray queries, compute derivatives),
// their feature structs chained from `tail`. Not copyable: the chain points into it.
struct OptionalExtensions {
    VkPhysicalDeviceMeshShaderFeaturesEXT mesh{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_MESH_SHADER_FEATURES_EXT};
    VkPhysicalDeviceRayQueryFeaturesKHR rayQuery{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
    VkPhysicalDeviceAccelerationStructureFeaturesKHR accel{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
    VkPhysicalDeviceComputeShaderDerivativesFeaturesNV derivs{
        VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_COMPUTE_SHADER_DERIVATIVES_FEATURES_NV};
    std::vector<const char*> deviceExts;
    void* tail = nullptr;
    OptionalExtensions() = default;
    OptionalExtensions(const OptionalExtensions&) = delete;
    OptionalExtensions& operator=(const OptionalExtensions&) = delete;
};

void chainOptionalExtensions(Device& device, const std::vector<VkExtensionProperties>& available,
                             OptionalExtensions& o) {
    if (hasExtension(available, VK_EXT_MESH_SHADER_EXTENSION_NAME)) {
        VkPhysicalDeviceFeatures2 q{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        q.pNext = &o.mesh;
        vkGetPhysicalDeviceFeatures2(device.physical, &q);
        if (o.mesh.meshShader && o.mesh.taskShader) {
            o.mesh.multiviewMeshShader = VK_FALSE;
            o.mesh.primitiveFragmentShadingRateMeshShader = VK_FALSE;
            o.mesh.meshShaderQueries = VK_FALSE;
            o.deviceExts.push_back(VK_EXT_MESH_SHADER_EXTENSION_NAME);
            o.mesh.pNext = o.tail;
            o.tail = &o.mesh;
            device.optional.meshShader = true;
        }
    }
    // SHADEL_DISABLE_RAY_QUERY=1 leaves ray tracing off, as on a device without it (tests of
    // the --rt-* error path on a device that has it).
    const char* noRayQuery = std::getenv("SHADEL_DISABLE_RAY_QUERY");
    bool rayQueryAllowed = !noRayQuery || std::strcmp(noRayQuery, "1") != 0;
    if (rayQueryAllowed && hasExtension(available, VK_KHR_RAY_QUERY_EXTENSION_NAME) &&
        hasExtension(available, VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME) &&
        hasExtension(available, VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME)) {
        VkPhysicalDeviceFeatures2 q{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        q.pNext = &o.rayQuery;
        o.rayQuery.pNext = &o.accel;
        vkGetPhysicalDeviceFeatures2(device.physical, &q);
        if (o.rayQuery.rayQuery && o.accel.accelerationStructure) {
            o.deviceExts.push_back(VK_KHR_RAY_QUERY_EXTENSION_NAME);
            o.deviceExts.push_back(VK_KHR_ACCELERATION_STRUCTURE_EXTENSION_NAME);
            o.deviceExts.push_back(VK_KHR_DEFERRED_HOST_OPERATIONS_EXTENSION_NAME);
            VkPhysicalDeviceRayQueryFeaturesKHR rq{
                VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
            o.rayQuery = rq;
            o.rayQuery.rayQuery = VK_TRUE;
            VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
                VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
            o.accel = as;
            o.accel.accelerationStructure = VK_TRUE;
            o.rayQuery.pNext = &o.accel;
            o.accel.pNext = o.tail;
            o.tail = &o.rayQuery;
            device.optional.rayQuery = true;
        } else {
            o.rayQuery.pNext = nullptr;
        }
    }
    if (hasExtension(available, VK_NV_COMPUTE_SHADER_DERIVATIVES_EXTENSION_NAME)) {
        VkPhysicalDeviceFeatures2 q{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
        q.pNext = &o.derivs;
        vkGetPhysicalDeviceFeatures2(device.physical, &q);
        if (o.derivs.computeDerivativeGroupQuads) {
            o.deviceExts.push_back(VK_NV_COMPUTE_SHADER_DERIVATIVES_EXTENSION_NAME);
            o.derivs.computeDerivativeGroupLinear = VK_FALSE;
            o.derivs.pNext = o.tail;
            o.tail = &o.derivs;
            device.optional.computeDerivatives = true;
        }
    }
}

} // namespace

void createDevice(Device& device, const DeviceDesc& desc) {
    createInstance(device, desc);
    std::vector<VkQueueFamilyProperties> families = describePhysicalDevice(device, desc);
    FeatureChain enable;
    requiredFeatures(device, families, enable);
    auto exts = deviceExtensions(device.physical);
    OptionalExtensions optional;
    chainOptionalExtensions(device, exts, optional);
    std::vector<const char*>& deviceExts = optional.deviceExts;
    enable.v13.pNext = optional.tail;

    float priority = 1.0f;
    VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    qci.queueFamilyIndex = device.queueFamily;
    qci.queueCount = 1;
    qci.pQueuePriorities = &priority;
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &enable.core;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &qci;
    if (desc.swapchain) {
        if (!hasExtension(exts, VK_KHR_SWAPCHAIN_EXTENSION_NAME))
            throw DeviceError(
                format("%s has no VK_KHR_swapchain: cannot open a window", device.name.c_str()));
        deviceExts.push_back(VK_KHR_SWAPCHAIN_EXTENSION_NAME);
    }
    dci.enabledExtensionCount = uint32_t(deviceExts.size());
    dci.ppEnabledExtensionNames = deviceExts.data();
    VkResult r = vkCreateDevice(device.physical, &dci, nullptr, &device.device);
    if (r != VK_SUCCESS)
        throw DeviceError(format("cannot create the Vulkan device on %s (%s)", device.name.c_str(),
                                 vkResultName(r)));
    vkGetDeviceQueue(device.device, device.queueFamily, 0, &device.queue);
    setName(device, device.queue, VK_OBJECT_TYPE_QUEUE, "mainQueue");
    SHADEL_DEBUG("device: %s (%s)", device.name.c_str(), device.driver.c_str());
}

void destroyDevice(Device& device) {
    if (device.device) vkDestroyDevice(device.device, nullptr);
    if (device.messenger) {
        auto destroy = (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(
            device.instance, "vkDestroyDebugUtilsMessengerEXT");
        if (destroy) destroy(device.instance, device.messenger, nullptr);
    }
    if (device.instance) vkDestroyInstance(device.instance, nullptr);
    device.device = VK_NULL_HANDLE;
    device.instance = VK_NULL_HANDLE;
    device.messenger = VK_NULL_HANDLE;
}

std::string describeDevice(const Device& device) {
    const VkPhysicalDeviceLimits& l = device.properties.limits;
    std::string out;
    out +=
        format("device:   %s (%s)\n", device.name.c_str(), typeName(device.properties.deviceType));
    out += format("driver:   %s\n", device.driver.c_str());
    out += format("api:      %u.%u.%u\n", VK_API_VERSION_MAJOR(device.properties.apiVersion),
                  VK_API_VERSION_MINOR(device.properties.apiVersion),
                  VK_API_VERSION_PATCH(device.properties.apiVersion));
    out += "required: dynamicRendering synchronization2 timelineSemaphore descriptorIndexing "
           "bufferDeviceAddress shaderInt64 shaderBufferInt64Atomics fragmentStoresAndAtomics "
           "multiDrawIndirect drawIndirectCount timestamps subgroups: all present\n";
    out +=
        format("optional: meshShader=%s rayQuery=%s computeDerivatives=%s sparseResidency=%s "
               "textureCompressionBC=%s\n",
               device.optional.meshShader ? "yes" : "no", device.optional.rayQuery ? "yes" : "no",
               device.optional.computeDerivatives ? "yes" : "no",
               device.optional.sparseResidency ? "yes" : "no",
               device.optional.textureCompressionBC ? "yes" : "no");
    out += format("limits:   maxImageDimension2D=%u maxComputeWorkGroupInvocations=%u "
                  "maxPushConstantsSize=%u maxDescriptorSetUpdateAfterBindSampledImages=%u "
                  "timestampPeriod=%.3fns\n",
                  l.maxImageDimension2D, l.maxComputeWorkGroupInvocations, l.maxPushConstantsSize,
                  l.maxPerStageDescriptorSampledImages, double(l.timestampPeriod));
    uint64_t heapTotal = 0;
    for (uint32_t i = 0; i < device.memory.memoryHeapCount; ++i)
        if (device.memory.memoryHeaps[i].flags & VK_MEMORY_HEAP_DEVICE_LOCAL_BIT)
            heapTotal += device.memory.memoryHeaps[i].size;
    out += format("memory:   %.1f GiB device-local\n", double(heapTotal) / (1 << 30));
    return out;
}

} // namespace shadel
