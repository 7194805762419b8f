// Readback and output: the GI image copied back to the CPU as floats, written as a raw RGBA
// float32 file, and its mean radiance (what the run prints and checks is not black).

#pragma once

#include "resources.hpp"
#include "vulkan_host.hpp"

#include <string>
#include <vector>

namespace capi_host {

// The RGBA16F `image`, left by shine in copy_source() (lending.hpp), as RGBA float texels, row
// by row.
std::vector<float> read_rgba16f(const HostDevice& host, const Submitter& s,
                                const HostImage& image);

// Writes `rgba` as little-endian float32 to `path`, through `path`.partial and a rename so no
// reader ever sees half a file.
void write_raw(const std::string& path, const std::vector<float>& rgba);

// The mean over pixels of (r + g + b) / 3.
double mean_rgb(const std::vector<float>& rgba);

}  // namespace capi_host
