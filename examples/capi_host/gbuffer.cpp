// The G-buffer: creating its targets and raster pipeline, and recording its pass.

#include "gbuffer.hpp"

#include "errors.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace capi_host {
namespace {

// The targets' formats, the Rust host's.
const VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;
const VkFormat kNormalFormat = VK_FORMAT_A2B10G10R10_UNORM_PACK32;  // n * 0.5 + 0.5
const VkFormat kAlbedoFormat = VK_FORMAT_R8G8B8A8_SRGB;             // decoded to linear on reads
const VkFormat kMaterialFormat = VK_FORMAT_R8G8B8A8_UNORM;          // r roughness, g metallic
const VkFormat kRadianceFormat = VK_FORMAT_R16G16B16A16_SFLOAT;     // direct and GI light

// The shaders' push constants (128 bytes, std430-compatible layout of the GLSL block).
struct DrawConstants {
    Mat4 view_proj;
    std::array<float, 4> base_color_roughness;
    std::array<float, 4> light_position_metallic;
    std::array<float, 4> light_intensity;
    std::array<float, 4> light_direction_cos_outer;
};
static_assert(sizeof(DrawConstants) == 128, "the shaders' push-constant block is 128 bytes");

const VkShaderStageFlags kPushStages = VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT;

// A shader module from the SPIR-V file at `path`.
VkShaderModule load_shader(const HostDevice& host, const std::string& path) {
    std::ifstream file(path, std::ios::binary);
    if (!file) fail("cannot open " + path);
    const std::vector<char> bytes((std::istreambuf_iterator<char>(file)),
                                  std::istreambuf_iterator<char>());
    if (bytes.empty() || bytes.size() % 4 != 0) fail(path + " is not SPIR-V");
    std::vector<uint32_t> code(bytes.size() / 4);
    std::memcpy(code.data(), bytes.data(), bytes.size());
    VkShaderModuleCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO;
    info.codeSize = bytes.size();
    info.pCode = code.data();
    VkShaderModule module = VK_NULL_HANDLE;
    check_vk(vkCreateShaderModule(host.device, &info, nullptr, &module), "vkCreateShaderModule");
    return module;
}

// A barrier taking `image` (contents discarded) from any earlier use to its attachment layout.
VkImageMemoryBarrier2 to_attachment(const HostImage& image, VkPipelineStageFlags2 stage,
                                    VkAccessFlags2 access, VkImageLayout layout,
                                    VkImageAspectFlags aspect) {
    VkImageMemoryBarrier2 b{};
    b.sType = VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER_2;
    b.srcStageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
    b.dstStageMask = stage;
    b.dstAccessMask = access;
    b.oldLayout = VK_IMAGE_LAYOUT_UNDEFINED;
    b.newLayout = layout;
    b.srcQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image.image;
    b.subresourceRange = whole(aspect);
    return b;
}

}  // namespace

Targets create_targets(const HostDevice& host, uint32_t width, uint32_t height) {
    const VkImageUsageFlags sampled = VK_IMAGE_USAGE_SAMPLED_BIT;
    const VkImageUsageFlags color = VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | sampled;
    Targets t;
    t.depth = create_image(host, kDepthFormat, width, height,
                           VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | sampled);
    t.normal = create_image(host, kNormalFormat, width, height, color);
    t.albedo = create_image(host, kAlbedoFormat, width, height, color);
    t.material = create_image(host, kMaterialFormat, width, height, color);
    t.direct = create_image(host, kRadianceFormat, width, height,
                            VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT);
    // shine blits into it, the host copies it out (and would sample it in a composite).
    t.gi = create_image(host, kRadianceFormat, width, height,
                        VK_IMAGE_USAGE_TRANSFER_DST_BIT | VK_IMAGE_USAGE_TRANSFER_SRC_BIT |
                            VK_IMAGE_USAGE_SAMPLED_BIT);
    return t;
}

void destroy_targets(const HostDevice& host, Targets& t) {
    for (HostImage* i : {&t.depth, &t.normal, &t.albedo, &t.material, &t.direct, &t.gi}) {
        destroy_image(host, *i);
    }
}

Raster create_raster(const HostDevice& host, const std::string& shader_dir) {
    Raster r;
    VkPushConstantRange push{kPushStages, 0, sizeof(DrawConstants)};
    VkPipelineLayoutCreateInfo layout{};
    layout.sType = VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO;
    layout.pushConstantRangeCount = 1;
    layout.pPushConstantRanges = &push;
    check_vk(vkCreatePipelineLayout(host.device, &layout, nullptr, &r.layout),
             "vkCreatePipelineLayout");

    const VkShaderModule vert = load_shader(host, shader_dir + "/gbuffer.vert.spv");
    const VkShaderModule frag = load_shader(host, shader_dir + "/gbuffer.frag.spv");
    std::array<VkPipelineShaderStageCreateInfo, 2> stages{};
    for (auto& stage : stages) {
        stage.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO;
        stage.pName = "main";
    }
    stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
    stages[0].module = vert;
    stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
    stages[1].module = frag;

    const VkVertexInputBindingDescription binding{0, 6 * sizeof(float),
                                                  VK_VERTEX_INPUT_RATE_VERTEX};
    const std::array<VkVertexInputAttributeDescription, 2> attributes{{
        {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},                  // position
        {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)},  // normal
    }};
    VkPipelineVertexInputStateCreateInfo vertex_input{};
    vertex_input.sType = VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO;
    vertex_input.vertexBindingDescriptionCount = 1;
    vertex_input.pVertexBindingDescriptions = &binding;
    vertex_input.vertexAttributeDescriptionCount = uint32_t(attributes.size());
    vertex_input.pVertexAttributeDescriptions = attributes.data();

    VkPipelineInputAssemblyStateCreateInfo assembly{};
    assembly.sType = VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO;
    assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;

    VkPipelineViewportStateCreateInfo viewport{};  // Viewport and scissor are dynamic.
    viewport.sType = VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO;
    viewport.viewportCount = 1;
    viewport.scissorCount = 1;

    VkPipelineRasterizationStateCreateInfo raster{};
    raster.sType = VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO;
    raster.polygonMode = VK_POLYGON_MODE_FILL;
    raster.cullMode = VK_CULL_MODE_NONE;
    raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;
    raster.lineWidth = 1.0f;

    VkPipelineMultisampleStateCreateInfo multisample{};
    multisample.sType = VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO;
    multisample.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;

    VkPipelineDepthStencilStateCreateInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO;
    depth.depthTestEnable = VK_TRUE;
    depth.depthWriteEnable = VK_TRUE;
    depth.depthCompareOp = VK_COMPARE_OP_LESS_OR_EQUAL;

    std::array<VkPipelineColorBlendAttachmentState, 4> blend{};
    for (auto& attachment : blend) {
        attachment.colorWriteMask = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                    VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
    }
    VkPipelineColorBlendStateCreateInfo blend_state{};
    blend_state.sType = VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO;
    blend_state.attachmentCount = uint32_t(blend.size());
    blend_state.pAttachments = blend.data();

    const std::array<VkDynamicState, 2> dynamic_states{VK_DYNAMIC_STATE_VIEWPORT,
                                                       VK_DYNAMIC_STATE_SCISSOR};
    VkPipelineDynamicStateCreateInfo dynamic{};
    dynamic.sType = VK_STRUCTURE_TYPE_PIPELINE_DYNAMIC_STATE_CREATE_INFO;
    dynamic.dynamicStateCount = uint32_t(dynamic_states.size());
    dynamic.pDynamicStates = dynamic_states.data();

    // Dynamic rendering: the attachments' formats instead of a render pass.
    const std::array<VkFormat, 4> formats{kNormalFormat, kAlbedoFormat, kMaterialFormat,
                                          kRadianceFormat};
    VkPipelineRenderingCreateInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_PIPELINE_RENDERING_CREATE_INFO;
    rendering.colorAttachmentCount = uint32_t(formats.size());
    rendering.pColorAttachmentFormats = formats.data();
    rendering.depthAttachmentFormat = kDepthFormat;

    VkGraphicsPipelineCreateInfo info{};
    info.sType = VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO;
    info.pNext = &rendering;
    info.stageCount = uint32_t(stages.size());
    info.pStages = stages.data();
    info.pVertexInputState = &vertex_input;
    info.pInputAssemblyState = &assembly;
    info.pViewportState = &viewport;
    info.pRasterizationState = &raster;
    info.pMultisampleState = &multisample;
    info.pDepthStencilState = &depth;
    info.pColorBlendState = &blend_state;
    info.pDynamicState = &dynamic;
    info.layout = r.layout;
    check_vk(vkCreateGraphicsPipelines(host.device, host.cache, 1, &info, nullptr, &r.pipeline),
             "vkCreateGraphicsPipelines");
    vkDestroyShaderModule(host.device, vert, nullptr);
    vkDestroyShaderModule(host.device, frag, nullptr);
    return r;
}

void destroy_raster(const HostDevice& host, Raster& r) {
    vkDestroyPipeline(host.device, r.pipeline, nullptr);
    vkDestroyPipelineLayout(host.device, r.layout, nullptr);
}

void record_raster(VkCommandBuffer cb, const Raster& raster, const Targets& targets,
                   const HostScene& scene, const Mat4& view_proj) {
    const std::array<const HostImage*, 4> colors{&targets.normal, &targets.albedo,
                                                 &targets.material, &targets.direct};
    std::array<VkImageMemoryBarrier2, 5> barriers{};
    std::array<VkRenderingAttachmentInfo, 4> attachments{};
    for (size_t i = 0; i < colors.size(); ++i) {
        barriers[i] = to_attachment(*colors[i], VK_PIPELINE_STAGE_2_COLOR_ATTACHMENT_OUTPUT_BIT,
                                    VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT,
                                    VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                                    VK_IMAGE_ASPECT_COLOR_BIT);
        attachments[i].sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
        attachments[i].imageView = colors[i]->view;
        attachments[i].imageLayout = VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
        attachments[i].loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;  // cleared to 0
        attachments[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    }
    barriers[4] = to_attachment(targets.depth,
                                VK_PIPELINE_STAGE_2_EARLY_FRAGMENT_TESTS_BIT |
                                    VK_PIPELINE_STAGE_2_LATE_FRAGMENT_TESTS_BIT,
                                VK_ACCESS_2_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT,
                                VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL,
                                VK_IMAGE_ASPECT_DEPTH_BIT);
    VkRenderingAttachmentInfo depth{};
    depth.sType = VK_STRUCTURE_TYPE_RENDERING_ATTACHMENT_INFO;
    depth.imageView = targets.depth.view;
    depth.imageLayout = VK_IMAGE_LAYOUT_DEPTH_ATTACHMENT_OPTIMAL;
    depth.loadOp = VK_ATTACHMENT_LOAD_OP_CLEAR;
    depth.storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    depth.clearValue.depthStencil = VkClearDepthStencilValue{1.0f, 0};  // standard Z: far is 1

    VkDependencyInfo dependency{};
    dependency.sType = VK_STRUCTURE_TYPE_DEPENDENCY_INFO;
    dependency.imageMemoryBarrierCount = uint32_t(barriers.size());
    dependency.pImageMemoryBarriers = barriers.data();
    vkCmdPipelineBarrier2(cb, &dependency);

    const VkRect2D area{{0, 0}, {targets.depth.width, targets.depth.height}};
    VkRenderingInfo rendering{};
    rendering.sType = VK_STRUCTURE_TYPE_RENDERING_INFO;
    rendering.renderArea = area;
    rendering.layerCount = 1;
    rendering.colorAttachmentCount = uint32_t(attachments.size());
    rendering.pColorAttachments = attachments.data();
    rendering.pDepthAttachment = &depth;
    vkCmdBeginRendering(cb, &rendering);

    // Not flipped: the projection is already Vulkan's (y down).
    const VkViewport viewport{0.0f, 0.0f, float(area.extent.width), float(area.extent.height),
                              0.0f, 1.0f};
    vkCmdSetViewport(cb, 0, 1, &viewport);
    vkCmdSetScissor(cb, 0, 1, &area);
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_GRAPHICS, raster.pipeline);
    const VkDeviceSize offset = 0;
    vkCmdBindVertexBuffers(cb, 0, 1, &scene.vertices.buffer, &offset);
    vkCmdBindIndexBuffer(cb, scene.indices.buffer, 0, VK_INDEX_TYPE_UINT32);
    for (const ShineDraw& draw : scene.draws) {
        // The C API does not expose the scene's lights, so the host draws without its direct
        // light, with the Rust host's no-light values (only the direct output depends on
        // them, and shine does not read it).
        DrawConstants c{};
        c.view_proj = view_proj;
        c.base_color_roughness = {draw.base_color[0], draw.base_color[1], draw.base_color[2],
                                  draw.roughness};
        c.light_position_metallic = {0.0f, 0.0f, 0.0f, draw.metallic};
        c.light_intensity = {0.0f, 0.0f, 0.0f, 0.0f};
        c.light_direction_cos_outer = {0.0f, -1.0f, 0.0f, -1.0f};  // pointing down, no cone
        vkCmdPushConstants(cb, raster.layout, kPushStages, 0, sizeof(c), &c);
        vkCmdDrawIndexed(cb, draw.index_count, 1, draw.first_index, 0, 0);
    }
    vkCmdEndRendering(cb);
}

}  // namespace capi_host
