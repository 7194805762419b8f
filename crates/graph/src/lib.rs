//! shine-graph: the render graph that schedules every pass of a shine frame.
//!
//! Knows Vulkan (through shine-gpu) but nothing of global illumination.
