/* C host 2: creates its own Vulkan instance and device (as a game engine would), hands them to
 * Kage, renders, and after Kage is gone goes on using and then destroys its device. With
 * validation on, the host's own messenger must see nothing, Kage's calls included.
 *
 * Usage: vulkan FRAMES SIZE VALIDATION TECHNIQUE (technique values as in kage_technique). */
#include <vulkan/vulkan.h>

#include "common.h"

#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned validation_messages;

static VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                                 VkDebugUtilsMessageTypeFlagsEXT types,
                                                 const VkDebugUtilsMessengerCallbackDataEXT *data,
                                                 void *user) {
  (void)severity, (void)types, (void)user;
  fprintf(stderr, "validation: %s\n", data->pMessage);
  validation_messages++;
  return VK_FALSE;
}

#define VK_CHECK(call) REQUIRE((call) == VK_SUCCESS)

/* A device on `physical` with one queue of `family`, with or without what Kage requires. */
static VkDevice make_device(VkPhysicalDevice physical, uint32_t family, int for_kage) {
  float priority = 1.0f;
  VkDeviceQueueCreateInfo queue = {VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO, NULL, 0, family, 1, &priority};
  const char *extensions[] = {VK_KHR_DYNAMIC_RENDERING_EXTENSION_NAME, VK_KHR_PUSH_DESCRIPTOR_EXTENSION_NAME};
  VkPhysicalDeviceDynamicRenderingFeatures dynamic_rendering = {
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DYNAMIC_RENDERING_FEATURES, NULL, VK_TRUE};
  VkPhysicalDeviceFeatures features = {0};
  features.shaderStorageImageExtendedFormats = VK_TRUE;
  VkDeviceCreateInfo info = {.sType = VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  info.queueCreateInfoCount = 1;
  info.pQueueCreateInfos = &queue;
  if (for_kage) {
    info.pNext = &dynamic_rendering;
    info.enabledExtensionCount = 2;
    info.ppEnabledExtensionNames = extensions;
    info.pEnabledFeatures = &features;
  }
  VkDevice device = VK_NULL_HANDLE;
  VK_CHECK(vkCreateDevice(physical, &info, NULL, &device));
  return device;
}

int main(int argc, char **argv) {
  if (argc != 5) {
    fprintf(stderr, "usage: %s FRAMES SIZE VALIDATION TECHNIQUE\n", argv[0]);
    return 2;
  }
  unsigned frames = (unsigned)atoi(argv[1]), size = (unsigned)atoi(argv[2]);
  int validation = atoi(argv[3]) != 0;

  VkApplicationInfo app = {VK_STRUCTURE_TYPE_APPLICATION_INFO, NULL, "kage-c-host", 1, NULL, 0, VK_API_VERSION_1_3};
  VkDebugUtilsMessengerCreateInfoEXT messenger_info = {.sType = VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger_info.messageSeverity =
      VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  messenger_info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                               VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger_info.pfnUserCallback = on_message;
  const char *layer = "VK_LAYER_KHRONOS_validation";
  const char *debug_utils = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
  VkInstanceCreateInfo instance_info = {.sType = VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  instance_info.pApplicationInfo = &app;
  if (validation) {
    /* Chained here too, so that instance creation and destruction are watched as well. */
    instance_info.pNext = &messenger_info;
    instance_info.enabledLayerCount = 1;
    instance_info.ppEnabledLayerNames = &layer;
    instance_info.enabledExtensionCount = 1;
    instance_info.ppEnabledExtensionNames = &debug_utils;
  }
  VkInstance instance = VK_NULL_HANDLE;
  VK_CHECK(vkCreateInstance(&instance_info, NULL, &instance));
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  PFN_vkDestroyDebugUtilsMessengerEXT destroy_messenger = NULL;
  if (validation) {
    PFN_vkCreateDebugUtilsMessengerEXT create_messenger =
        (PFN_vkCreateDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT");
    destroy_messenger =
        (PFN_vkDestroyDebugUtilsMessengerEXT)vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT");
    REQUIRE(create_messenger && destroy_messenger);
    VK_CHECK(create_messenger(instance, &messenger_info, NULL, &messenger));
  }

  /* The device KAGE_DEVICE names, else the first with a graphics and compute queue. */
  VkPhysicalDevice physicals[16];
  uint32_t physical_count = 16;
  REQUIRE(vkEnumeratePhysicalDevices(instance, &physical_count, physicals) >= VK_SUCCESS);
  const char *wanted = getenv("KAGE_DEVICE");
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  uint32_t family = UINT32_MAX;
  for (uint32_t d = 0; d < physical_count && physical == VK_NULL_HANDLE; d++) {
    VkPhysicalDeviceProperties props;
    vkGetPhysicalDeviceProperties(physicals[d], &props);
    if (wanted && !strstr(props.deviceName, wanted)) continue;
    VkQueueFamilyProperties families[16];
    uint32_t family_count = 16;
    vkGetPhysicalDeviceQueueFamilyProperties(physicals[d], &family_count, families);
    for (uint32_t f = 0; f < family_count; f++) {
      VkQueueFlags both = VK_QUEUE_GRAPHICS_BIT | VK_QUEUE_COMPUTE_BIT;
      if ((families[f].queueFlags & both) == both) {
        physical = physicals[d], family = f;
        break;
      }
    }
  }
  REQUIRE(physical != VK_NULL_HANDLE);

  /* A device without Kage's extensions is refused with a reason, not crashed on. */
  VkDevice bare = make_device(physical, family, 0);
  VkQueue bare_queue;
  vkGetDeviceQueue(bare, family, 0, &bare_queue);
  kage_vulkan_handles handles = {sizeof(kage_vulkan_handles), instance, physical, bare, family, bare_queue, validation};
  kage_context *context = NULL;
  EXPECT(kage_context_create_from_vulkan(&handles, &context), KAGE_RESULT_UNSUPPORTED);
  char message[512];
  CHECK(kage_last_error_message(message, sizeof message, NULL));
  REQUIRE(strstr(message, "VK_KHR_dynamic_rendering enabled on the host's device") != NULL);
  vkDestroyDevice(bare, NULL);

  VkDevice device = make_device(physical, family, 1);
  VkQueue queue;
  vkGetDeviceQueue(device, family, 0, &queue);
  handles.device = device, handles.queue = queue;
  CHECK(kage_context_create_from_vulkan(&handles, &context));
  render_moving_box(context, (uint32_t)atoi(argv[4]), frames, size);
  CHECK(kage_context_destroy(context));

  /* Kage is gone; the device is still the host's, and works. */
  VkBufferCreateInfo buffer_info = {.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  buffer_info.size = 256;
  buffer_info.usage = VK_BUFFER_USAGE_TRANSFER_DST_BIT;
  VkBuffer buffer;
  VK_CHECK(vkCreateBuffer(device, &buffer_info, NULL, &buffer));
  vkDestroyBuffer(device, buffer, NULL);
  VK_CHECK(vkQueueWaitIdle(queue));
  vkDestroyDevice(device, NULL);
  if (validation) destroy_messenger(instance, messenger, NULL);
  vkDestroyInstance(instance, NULL);
  REQUIRE(validation_messages == 0);
  printf("ok\n");
  return 0;
}
