//! Deferred destruction: a dropped resource is destroyed only once every submission that was
//! recorded before the drop has completed on the GPU.
//!
//! Each submission gets a serial. A dropped object is tagged with the newest serial handed out
//! (or, while a command buffer is being recorded, held until every open recording has been
//! submitted or abandoned); [`Device::retire`] polls the fences of submissions in flight,
//! advances the completed serial and destroys what is old enough.
//!
//! Only submissions made through [`Device::submit`] are known here. A host that records shine
//! work into its own command buffers must keep shine objects alive until that work completes
//! (the render graph's executor does this for its own resources).

use crate::commands::Context;
use crate::device::{Device, lock};
use crate::error::{Result, VkContext};
use ash::vk;
use gpu_allocator::vulkan::{Allocation, Allocator};
use std::collections::VecDeque;

/// A Vulkan object waiting for the GPU to finish with it.
pub(crate) enum Garbage {
    Buffer(vk::Buffer, Option<Allocation>),
    Image(vk::Image, vk::ImageView, Option<Allocation>),
    Memory(Allocation),
    Pipeline(vk::Pipeline),
    PipelineLayout(vk::PipelineLayout, Vec<vk::DescriptorSetLayout>),
    Sampler(vk::Sampler),
}

impl Garbage {
    fn destroy(self, device: &ash::Device, allocator: &mut Allocator) {
        // SAFETY (all arms): the object was created on `device` and the GPU is done with it.
        match self {
            Self::Buffer(buffer, allocation) => {
                unsafe { device.destroy_buffer(buffer, None) };
                if let Some(a) = allocation {
                    let _ = allocator.free(a);
                }
            }
            Self::Image(image, view, allocation) => {
                unsafe {
                    device.destroy_image_view(view, None);
                    device.destroy_image(image, None);
                }
                if let Some(a) = allocation {
                    let _ = allocator.free(a);
                }
            }
            Self::Memory(a) => {
                let _ = allocator.free(a);
            }
            Self::Pipeline(pipeline) => unsafe { device.destroy_pipeline(pipeline, None) },
            Self::PipelineLayout(layout, set_layouts) => unsafe {
                device.destroy_pipeline_layout(layout, None);
                for l in set_layouts {
                    device.destroy_descriptor_set_layout(l, None);
                }
            },
            Self::Sampler(sampler) => unsafe { device.destroy_sampler(sampler, None) },
        }
    }
}

/// Submission serials, objects awaiting destruction and recyclable command contexts.
#[derive(Default)]
pub(crate) struct Tracker {
    /// Serial of the newest submission.
    pub submitted: u64,
    /// Every submission up to this serial has completed.
    pub completed: u64,
    /// Fences of submissions not yet seen complete, oldest first.
    pub in_flight: VecDeque<(u64, vk::Fence)>,
    garbage: Vec<(u64, Garbage)>,
    /// Dropped while a recording was open: stamped with a serial once none is.
    held: Vec<Garbage>,
    /// Contexts ready for reuse.
    pub free_contexts: Vec<Context>,
    /// Contexts of submissions dropped without waiting, with their serial.
    pub orphaned: Vec<(u64, Context)>,
    /// Command buffers being recorded: an object dropped now may be used by their submission.
    pub recording: usize,
}

impl Tracker {
    /// A recording was submitted (`submitted` already counts it) or abandoned. Once no
    /// recording is open, everything dropped meanwhile can only be used by submissions up to
    /// the newest one.
    pub(crate) fn recording_closed(&mut self) {
        self.recording = self.recording.saturating_sub(1);
        if self.recording == 0 {
            let serial = self.submitted;
            let held = std::mem::take(&mut self.held);
            self.garbage.extend(held.into_iter().map(|g| (serial, g)));
        }
    }
}

impl Tracker {
    /// Destroys everything; the device must be idle.
    pub(crate) fn destroy_all(&mut self, device: &ash::Device, allocator: &mut Allocator) {
        let garbage = self
            .garbage
            .drain(..)
            .map(|(_, g)| g)
            .chain(self.held.drain(..));
        for g in garbage {
            g.destroy(device, allocator);
        }
        let contexts = self
            .free_contexts
            .drain(..)
            .chain(self.orphaned.drain(..).map(|(_, c)| c));
        for c in contexts {
            c.destroy(device);
        }
    }
}

impl Device {
    /// Hands an object over for destruction once the GPU can no longer be using it.
    pub(crate) fn defer(&self, garbage: Garbage) {
        let mut tracker = lock(&self.inner.tracker);
        if tracker.recording > 0 {
            // An open recording may use it; its serial is known only once it is submitted.
            tracker.held.push(garbage);
        } else if tracker.completed == tracker.submitted {
            drop(tracker);
            garbage.destroy(&self.inner.raw, &mut self.allocator());
        } else {
            let serial = tracker.submitted;
            tracker.garbage.push((serial, garbage));
        }
    }

    /// Objects dropped but not yet destroyed because the GPU may still use them.
    pub fn pending_destructions(&self) -> usize {
        let tracker = lock(&self.inner.tracker);
        tracker.garbage.len() + tracker.held.len()
    }

    /// Polls submissions in flight and destroys or recycles what they no longer use.
    pub fn retire(&self) -> Result<()> {
        let mut tracker = lock(&self.inner.tracker);
        while let Some(&(serial, fence)) = tracker.in_flight.front() {
            // SAFETY: the fence belongs to a live context of this device.
            let done = unsafe { self.inner.raw.get_fence_status(fence) }
                .ctx("polling a submission fence")?;
            if !done {
                break;
            }
            tracker.completed = serial;
            tracker.in_flight.pop_front();
        }
        let completed = tracker.completed;
        let (ready, waiting): (Vec<_>, Vec<_>) = tracker
            .garbage
            .drain(..)
            .partition(|(serial, _)| *serial <= completed);
        tracker.garbage = waiting;
        let (free, orphaned): (Vec<_>, Vec<_>) = tracker
            .orphaned
            .drain(..)
            .partition(|(serial, _)| *serial <= completed);
        tracker.orphaned = orphaned;
        tracker
            .free_contexts
            .extend(free.into_iter().map(|(_, c)| c));
        drop(tracker);
        if !ready.is_empty() {
            let mut allocator = self.allocator();
            for (_, g) in ready {
                g.destroy(&self.inner.raw, &mut allocator);
            }
        }
        Ok(())
    }
}
