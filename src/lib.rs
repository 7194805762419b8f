//! shine: a real-time soft global-illumination engine on Vulkan 1.3.
