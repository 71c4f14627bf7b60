// The demo's offscreen Vulkan renderer: triangle lists with per-vertex normal and colour, drawn
// with Lambert shading into an RGBA8 image that is read back to memory. It runs on the device
// the OpenXR session uses (lavapipe on a machine without a GPU). Not part of the layer.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

namespace sdfg::demo {

struct Vertex {
  glm::vec3 position;
  glm::vec3 normal;  // zero: drawn unlit in its colour
  glm::vec3 colour;  // linear 0..1, written as is (UNORM target)
};

// Two triangle lists: `lit` is depth-tested, `overlay` is drawn last without a depth test so
// markers (contact points) stay visible through the object.
struct DrawList {
  std::vector<Vertex> lit;
  std::vector<Vertex> overlay;
};

class Renderer {
 public:
  Renderer() = default;
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // The device, a queue family with graphics and a queue of it; the caller keeps them alive
  // longer than the renderer and does not use the queue at the same time.
  bool init(VkPhysicalDevice physical, VkDevice device, uint32_t queueFamily, VkQueue queue,
            std::string& error);

  // Draws `list` with `viewProjection` (Vulkan clip space: y down, depth 0..1) into a
  // width x height image cleared to `background`; `rgba` receives width * height * 4 bytes,
  // top row first.
  bool render(const DrawList& list, const glm::mat4& viewProjection, const glm::vec3& light,
              uint32_t width, uint32_t height, const glm::vec3& background,
              std::vector<uint8_t>& rgba, std::string& error);

 private:
  struct Buffer {
    VkBuffer buffer = VK_NULL_HANDLE;
    VkDeviceMemory memory = VK_NULL_HANDLE;
    VkDeviceSize size = 0;
    void* mapped = nullptr;
  };
  bool createPipelines(std::string& error);
  bool ensureTarget(uint32_t width, uint32_t height, std::string& error);
  void destroyTarget();
  bool ensureBuffer(Buffer& b, VkDeviceSize size, VkBufferUsageFlags usage, std::string& error);
  void destroyBuffer(Buffer& b);
  int32_t memoryType(uint32_t bits, VkMemoryPropertyFlags flags) const;
  bool createImage(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect,
                   VkImage& image, VkDeviceMemory& memory, VkImageView& view, std::string& error);

  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  VkPhysicalDeviceMemoryProperties memory_{};

  VkRenderPass renderPass_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline litPipeline_ = VK_NULL_HANDLE;      // depth test and write
  VkPipeline overlayPipeline_ = VK_NULL_HANDLE;  // no depth test: markers on top
  VkCommandPool commandPool_ = VK_NULL_HANDLE;
  VkCommandBuffer commands_ = VK_NULL_HANDLE;
  VkFence fence_ = VK_NULL_HANDLE;  // waits for the frame before the readback is read

  uint32_t width_ = 0, height_ = 0;
  VkImage colour_ = VK_NULL_HANDLE, depth_ = VK_NULL_HANDLE;
  VkDeviceMemory colourMemory_ = VK_NULL_HANDLE, depthMemory_ = VK_NULL_HANDLE;
  VkImageView colourView_ = VK_NULL_HANDLE, depthView_ = VK_NULL_HANDLE;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  Buffer vertices_;  // host-visible vertex data of both lists
  Buffer readback_;  // host-visible copy of the colour image
};

}  // namespace sdfg::demo
