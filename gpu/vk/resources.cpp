#include "gpu/vk/resources.h"

#include <optional>
#include <string>

namespace sslpv::gpu {

std::uint32_t findMemoryType(const VkPhysicalDeviceMemoryProperties& memory, std::uint32_t typeBits,
                             VkMemoryPropertyFlags required, VkMemoryPropertyFlags preferred) {
  std::optional<std::uint32_t> fallback;
  for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i) {
    if (!(typeBits & (1u << i))) continue;
    const VkMemoryPropertyFlags flags = memory.memoryTypes[i].propertyFlags;
    if ((flags & required) != required) continue;
    if ((flags & preferred) == preferred) return i;
    if (!fallback) fallback = i;
  }
  if (fallback) return *fallback;
  throw GpuError("no Vulkan memory type with property flags " + std::to_string(required) + " for memory type bits " +
                 std::to_string(typeBits));
}

Buffer::Buffer(const VulkanDevice& device, VkDeviceSize size, VkBufferUsageFlags usage, MemoryUse use) : size_(size) {
  const VkDevice vk = device.handle();
  VkBufferCreateInfo info{};
  info.sType = VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO;
  info.size = size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  VkBuffer buffer = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkCreateBuffer(vk, &info, nullptr, &buffer));
  buffer_ = BufferHandle(vk, buffer);

  VkMemoryRequirements requirements;
  vkGetBufferMemoryRequirements(vk, buffer, &requirements);
  constexpr VkMemoryPropertyFlags hostAccess =
      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT;
  VkMemoryPropertyFlags required = 0, preferred = 0;
  if (use == MemoryUse::Host) {
    required = hostAccess;
    preferred = VK_MEMORY_PROPERTY_HOST_CACHED_BIT;  // readbacks are slow from uncached memory
  } else {
    required = VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT;
    preferred = device.unifiedMemory() ? hostAccess : 0;
  }
  const std::uint32_t type =
      findMemoryType(device.memoryProperties(), requirements.memoryTypeBits, required, preferred);
  VkMemoryAllocateInfo allocate{};
  allocate.sType = VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO;
  allocate.allocationSize = requirements.size;
  allocate.memoryTypeIndex = type;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  SSLPV_VK_CHECK(vkAllocateMemory(vk, &allocate, nullptr, &memory));
  memory_ = MemoryHandle(vk, memory);
  SSLPV_VK_CHECK(vkBindBufferMemory(vk, buffer, memory, 0));

  const VkMemoryPropertyFlags flags = device.memoryProperties().memoryTypes[type].propertyFlags;
  const bool mappable = (flags & hostAccess) == hostAccess;
  if (mappable && (use == MemoryUse::Host || device.unifiedMemory()))
    SSLPV_VK_CHECK(vkMapMemory(vk, memory, 0, VK_WHOLE_SIZE, 0, &mapped_));
}

}  // namespace sslpv::gpu
