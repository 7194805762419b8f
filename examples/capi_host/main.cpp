// capi_host: a C++ host engine that uses shine as its GI pass through the C API (shine.h).
//
// The host owns everything Vulkan: its instance (validation on where installed), device,
// queue, command pool, pipeline cache, G-buffer images and raster pipeline. It lends the
// device to shine, rasterises its own G-buffer each frame, records shine's dispatch into its
// own command buffer, submits, and reads the GI image back to a raw float file.
//
// The G-buffer is rasterised exactly as the Rust host of examples/host_gbuffer/host does
// (same shaders, formats, raster state, push constants and image states), so both hosts
// hand shine the same inputs and get the same GI.
//
// This file holds the run in order: the command line, the shine calls, the frame loop and the
// teardown; README.md lists the modules it calls.
//
// Usage: capi_host <scene> <width> <height> <frames> <out.raw> <shader_dir>

#include "errors.hpp"
#include "gbuffer.hpp"
#include "lending.hpp"
#include "readback.hpp"
#include "scene.hpp"
#include "vulkan_host.hpp"

#include <vulkan/vulkan.h>

#include "shine.h"

#include <cerrno>
#include <cstdint>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <string>
#include <vector>

using namespace capi_host;

namespace {

// An internal resolution that is not offered (60 %) must be refused with INVALID_ARGUMENT and
// a message naming the ones there are, and no context made.
void check_bad_percent_is_refused(ShineDevice device, ShineContextDesc desc) {
    desc.internal_percent = 60;
    ShineContext context = nullptr;
    const ShineResult result = shine_context_create(device, &desc, &context);
    const std::string message = shine_last_error();
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT || context != nullptr ||
        message.find("75") == std::string::npos) {
        fail(std::string("a 60 % internal resolution was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "60 % refused: " << shine_result_name(result) << ": " << message << "\n";
}

// A dispatch whose view matrix holds a NaN must be refused with INVALID_ARGUMENT and a
// message; its command buffer is reset, never submitted.
void check_bad_input_is_refused(ShineContext context, const Submitter& s,
                                ShineDispatchDesc desc) {
    desc.camera.view[5] = std::numeric_limits<float>::quiet_NaN();
    begin(s);
    const ShineResult result = shine_context_dispatch(context, s.cb, &desc);
    const std::string message = shine_last_error();
    check_vk(vkResetCommandBuffer(s.cb, 0), "vkResetCommandBuffer");
    if (result != SHINE_RESULT_ERROR_INVALID_ARGUMENT || message.empty()) {
        fail(std::string("a NaN camera was not refused as it should be: got ") +
             shine_result_name(result) + " with message \"" + message + "\"");
    }
    std::cout << "NaN camera refused: " << shine_result_name(result) << ": " << message << "\n";
}

// One frame: the host's G-buffer, then shine's GI into the gi image, submitted and waited for.
void render_frame(const HostDevice& host, const Submitter& s, ShineContext context,
                  const Raster& raster, const Targets& targets, const HostScene& scene,
                  const ShineDispatchDesc& desc, const Mat4& view_proj) {
    begin(s);
    record_raster(s.cb, raster, targets, scene, view_proj);
    check_shine(shine_context_dispatch(context, s.cb, &desc), "shine_context_dispatch");
    submit_and_wait(host, s);
}

// The command line's arguments.
struct Options {
    std::string scene;
    uint32_t width = 0;
    uint32_t height = 0;
    uint32_t frames = 0;
    std::string output;
    std::string shader_dir;
};

// `text` as a whole number from 1 to 65536; anything else fails, naming `what`.
uint32_t positive(const char* text, const char* what) {
    char* end = nullptr;
    errno = 0;
    const unsigned long value = std::strtoul(text, &end, 10);
    if (errno != 0 || end == text || *end != '\0' || value == 0 || value > 1u << 16) {
        fail(std::string(what) + " must be a whole number from 1 to 65536, not \"" + text + "\"");
    }
    return static_cast<uint32_t>(value);
}

Options parse(int argc, char** argv) {
    if (argc != 7) {
        fail("usage: capi_host <scene> <width> <height> <frames> <out.raw> <shader_dir>\n"
             "  e.g. capi_host builtin:cornell-box 64 64 3 gi.raw build");
    }
    Options o;
    o.scene = argv[1];
    o.width = positive(argv[2], "width");
    o.height = positive(argv[3], "height");
    o.frames = positive(argv[4], "frames");
    o.output = argv[5];
    o.shader_dir = argv[6];
    return o;
}

}  // namespace

int main(int argc, char** argv) {
    const Options options = parse(argc, argv);
    ValidationLog validation;

    // The host's own Vulkan objects, then shine on its device.
    HostDevice host;
    create_instance(host, validation);
    pick_physical_device(host);
    create_device(host);
    ShineDevice shine_device = lend_to_shine(host);

    ShineScene scene = nullptr;
    check_shine(shine_scene_load(options.scene.c_str(), &scene), "shine_scene_load");
    HostScene host_scene = upload_scene(host, scene);
    const Camera camera = scene_camera(scene, options.width, options.height);
    const Mat4 view_proj = multiply(camera.projection, camera.view);
    Targets targets = create_targets(host, options.width, options.height);
    Raster raster = create_raster(host, options.shader_dir);
    Submitter submitter = create_submitter(host);

    // The GI context, with the settings of the Rust tests' `exact_desc` (no noise from the
    // frame index or the G-buffer's last bits).
    const char* settings[] = {"hvl.shadow_rays=0", "hvl.near_range=0"};
    ShineContextDesc context_desc{};
    context_desc.version = SHINE_CONTEXT_DESC_VERSION;
    context_desc.width = options.width;
    context_desc.height = options.height;
    context_desc.frames_in_flight = 2;
    context_desc.technique = "hvl";
    context_desc.settings = settings;
    context_desc.settings_count = 2;
    ShineContext context = nullptr;
    check_bad_percent_is_refused(shine_device, context_desc);
    check_shine(shine_context_create(shine_device, &context_desc, &context),
                "shine_context_create");
    // The host's own buffers and the scene's lights, not shine's copy of the scene: what an
    // engine with its geometry already on the GPU does.
    register_with_shine(context, scene, host_scene);
    check_shine(shine_context_warm_up(context, nullptr), "shine_context_warm_up");

    const ShineImage diffuse = lend(targets.gi, undefined_state(), copy_source());
    check_bad_input_is_refused(context, submitter, dispatch_desc(0, camera, targets, &diffuse));
    for (uint32_t k = 0; k < options.frames; ++k) {
        render_frame(host, submitter, context, raster, targets, host_scene,
                     dispatch_desc(k, camera, targets, &diffuse), view_proj);
        std::cout << "frame " << k + 1 << "/" << options.frames << "\n";
    }
    ShineMemoryReport memory{};
    check_shine(shine_context_memory_report(context, &memory), "shine_context_memory_report");
    std::cout << "shine holds " << memory.scene << " B of scene, " << memory.transients
              << " B of transients, " << memory.history << " B of history\n";
    const std::vector<float> gi = read_rgba16f(host, submitter, targets.gi);
    write_raw(options.output, gi);
    std::cout << "wrote " << options.output << " (" << options.width << "x" << options.height
              << " RGBA float32)\n";
    std::cout << "mean radiance: indirect " << mean_rgb(gi) << "\n";

    // Teardown: the GPU is idle, shine's objects go first, then the host's, then its device.
    check_vk(vkDeviceWaitIdle(host.device), "vkDeviceWaitIdle");
    check_shine(shine_context_destroy(context), "shine_context_destroy");
    check_shine(shine_scene_destroy(scene), "shine_scene_destroy");
    check_shine(shine_device_destroy(shine_device), "shine_device_destroy");
    destroy_submitter(host, submitter);
    destroy_raster(host, raster);
    destroy_targets(host, targets);
    destroy_scene(host, host_scene);
    destroy_host_device(host);

    if (!validation.messages.empty()) {
        std::cerr << "capi_host: " << validation.messages.size() << " validation message(s):\n";
        for (const std::string& message : validation.messages) std::cerr << "  " << message << "\n";
        return 1;
    }
    if (!(mean_rgb(gi) > 0.0)) fail("the GI image is black");
    std::cout << "validation: clean\n";
    return 0;
}
