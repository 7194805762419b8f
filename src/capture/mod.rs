//! Frames leaving the engine: image files (PNG, EXR), the tonemap curves and the image
//! metrics that compare a frame with its reference.

pub mod image_compare;
pub mod image_io;
pub mod noise_free;
pub mod regions;
pub mod sequence;
pub mod tonemap;
