// What the host lends shine: its device (shine_device_create), and each frame its G-buffer
// images with the states they are in before and after the dispatch (the Rust bench's
// `record_gbuffer`), gathered in the frame's ShineDispatchDesc.

#pragma once

#include "gbuffer.hpp"
#include "resources.hpp"
#include "scene.hpp"
#include "vulkan_host.hpp"

#include "shine.h"

#include <cstdint>

namespace capi_host {

// shine's handle on the host's device: the host keeps every object alive until it is gone.
ShineDevice lend_to_shine(const HostDevice& host);

// Where shine leaves the GI image: ready for the host's copy to the CPU.
ShineImageState copy_source();

// No earlier use: contents discarded.
ShineImageState undefined_state();

// `i` as shine sees it, in state `before` when the dispatch runs and `after` once it has.
ShineImage lend(const HostImage& i, ShineImageState before, ShineImageState after);

// Frame `frame`'s dispatch: a still camera, UNORM normals, glTF-style material channels, the
// indirect light into `diffuse` (which must outlive the dispatch call).
ShineDispatchDesc dispatch_desc(uint64_t frame, const Camera& camera, const Targets& t,
                                const ShineImage* diffuse);

}  // namespace capi_host
