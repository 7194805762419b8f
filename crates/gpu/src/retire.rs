//! Deferred destruction: a dropped resource is destroyed only once every submission that was
//! recorded before the drop has completed on the GPU.
//!
//! Each submission gets a serial. A dropped object is tagged with the newest serial handed out
//! (or, while a command buffer is being recorded, held until every open recording has been
//! submitted or abandoned); [`Device::retire`] polls the fences of submissions in flight,
//! advances the completed serial and destroys what is old enough.
//!
//! Submissions made through [`Device::submit`] are known here. A host that records shine work
//! into its own command buffers announces each of its frames with
//! [`Device::begin_host_frame`] and promises which have completed; from then on a dropped
//! object is also tagged with the host frame, and waits for that frame too.

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
    DescriptorPool(vk::DescriptorPool),
    QueryPool(vk::QueryPool),
}

/// Bytes and allocations freed by destroying objects that freed `sizes` bytes each (an
/// object frees at most one allocation; 0: none).
pub(crate) fn tally(sizes: impl IntoIterator<Item = u64>) -> (u64, usize) {
    sizes
        .into_iter()
        .filter(|&s| s > 0)
        .fold((0, 0), |(bytes, count), s| (bytes + s, count + 1))
}

/// Frees `allocation`, returning its size (shine's own count of the memory it holds).
pub(crate) fn free(allocator: &mut Allocator, allocation: Allocation) -> u64 {
    let size = allocation.size();
    let _ = allocator.free(allocation);
    size
}

impl Garbage {
    /// Bytes of device memory its destruction will free.
    fn bytes(&self) -> u64 {
        match self {
            Self::Buffer(_, Some(a)) | Self::Image(_, _, Some(a)) | Self::Memory(a) => a.size(),
            _ => 0,
        }
    }

    /// Destroys the object; returns the bytes of memory it freed.
    fn destroy(self, device: &ash::Device, allocator: &mut Allocator) -> u64 {
        // SAFETY (all arms): the object was created on `device` and the GPU is done with it.
        match self {
            Self::Buffer(buffer, allocation) => {
                unsafe { device.destroy_buffer(buffer, None) };
                allocation.map_or(0, |a| free(allocator, a))
            }
            Self::Image(image, view, allocation) => {
                unsafe {
                    device.destroy_image_view(view, None);
                    device.destroy_image(image, None);
                }
                allocation.map_or(0, |a| free(allocator, a))
            }
            Self::Memory(a) => free(allocator, a),
            Self::Pipeline(pipeline) => {
                unsafe { device.destroy_pipeline(pipeline, None) };
                0
            }
            Self::PipelineLayout(layout, set_layouts) => {
                unsafe {
                    device.destroy_pipeline_layout(layout, None);
                    for l in set_layouts {
                        device.destroy_descriptor_set_layout(l, None);
                    }
                }
                0
            }
            Self::Sampler(sampler) => {
                unsafe { device.destroy_sampler(sampler, None) };
                0
            }
            Self::DescriptorPool(pool) => {
                unsafe { device.destroy_descriptor_pool(pool, None) };
                0
            }
            Self::QueryPool(pool) => {
                unsafe { device.destroy_query_pool(pool, None) };
                0
            }
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
    /// With the host frame that was being recorded at the drop, if any.
    held: Vec<(Option<u64>, Garbage)>,
    /// Contexts ready for reuse.
    pub free_contexts: Vec<Context>,
    /// Contexts of submissions dropped without waiting, with their serial.
    pub orphaned: Vec<(u64, Context)>,
    /// Command buffers being recorded: an object dropped now may be used by their submission.
    pub recording: usize,
    /// The host frame being recorded ([`Device::begin_host_frame`]); `None` until a host
    /// records shine work into its own command buffers.
    host_frame: Option<u64>,
    /// Every host frame up to this one has completed on the GPU.
    host_completed: Option<u64>,
    /// Dropped while host frames were recorded: (host frame, shine serial, object), destroyed
    /// once both have completed.
    host_garbage: Vec<(u64, u64, Garbage)>,
}

impl Tracker {
    /// A recording was submitted (`submitted` already counts it) or abandoned. Once no
    /// recording is open, everything dropped meanwhile can only be used by submissions up to
    /// the newest one.
    pub(crate) fn recording_closed(&mut self) {
        self.recording = self.recording.saturating_sub(1);
        if self.recording == 0 {
            let serial = self.submitted;
            for (host_frame, g) in std::mem::take(&mut self.held) {
                match host_frame {
                    Some(frame) => self.host_garbage.push((frame, serial, g)),
                    None => self.garbage.push((serial, g)),
                }
            }
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
            .chain(self.held.drain(..).map(|(_, g)| g))
            .chain(self.host_garbage.drain(..).map(|(_, _, g)| g));
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

    /// Takes the host garbage whose host frame and shine serial have both completed.
    fn ready_host_garbage(&mut self) -> Vec<Garbage> {
        let (Some(host_done), done) = (self.host_completed, self.completed) else {
            return Vec::new();
        };
        let (ready, waiting): (Vec<_>, Vec<_>) = self
            .host_garbage
            .drain(..)
            .partition(|(frame, serial, _)| *frame <= host_done && *serial <= done);
        self.host_garbage = waiting;
        ready.into_iter().map(|(_, _, g)| g).collect()
    }
}

impl Device {
    /// Hands an object over for destruction once the GPU can no longer be using it.
    pub(crate) fn defer(&self, garbage: Garbage) {
        let mut tracker = lock(&self.inner.tracker);
        if tracker.recording > 0 {
            // An open recording may use it; its serial is known only once it is submitted.
            let host_frame = tracker.host_frame;
            tracker.held.push((host_frame, garbage));
        } else if let Some(frame) = tracker.host_frame {
            // The host's submissions of frames up to `frame` may use it.
            let serial = tracker.submitted;
            tracker.host_garbage.push((frame, serial, garbage));
        } else if tracker.completed == tracker.submitted {
            drop(tracker);
            self.destroy_now(vec![garbage]);
        } else {
            let serial = tracker.submitted;
            tracker.garbage.push((serial, garbage));
        }
    }

    /// Destroys a buffer whose memory is not its own (bound into a memory block) once the GPU
    /// can no longer be using it: the render graph's placed resources.
    pub fn defer_buffer(&self, buffer: vk::Buffer) {
        self.defer(Garbage::Buffer(buffer, None));
    }

    /// Destroys an image and its view (null: none) whose memory is not their own, once the
    /// GPU can no longer be using them.
    pub fn defer_image(&self, image: vk::Image, view: vk::ImageView) {
        self.defer(Garbage::Image(image, view, None));
    }

    /// Destroys `ready` (objects the GPU is done with) and counts the memory freed.
    fn destroy_now(&self, ready: Vec<Garbage>) {
        if ready.is_empty() {
            return;
        }
        let mut allocator = self.allocator();
        let freed = tally(
            ready
                .into_iter()
                .map(|g| g.destroy(&self.inner.raw, &mut allocator))
                .collect::<Vec<_>>(),
        );
        drop(allocator);
        self.freed(freed);
    }

    /// Bytes of device memory held by objects dropped but not yet destroyed.
    pub fn pending_destruction_bytes(&self) -> u64 {
        let tracker = lock(&self.inner.tracker);
        tracker
            .garbage
            .iter()
            .map(|(_, g)| g)
            .chain(tracker.held.iter().map(|(_, g)| g))
            .chain(tracker.host_garbage.iter().map(|(_, _, g)| g))
            .map(Garbage::bytes)
            .sum()
    }

    /// Objects dropped but not yet destroyed because the GPU may still use them.
    pub fn pending_destructions(&self) -> usize {
        let tracker = lock(&self.inner.tracker);
        tracker.garbage.len() + tracker.held.len() + tracker.host_garbage.len()
    }

    /// A host engine is about to record host frame `frame` with shine work into its own
    /// command buffers, and promises that every host frame up to `frame − frames_in_flight`
    /// has completed on the GPU. From the first call on, objects shine drops are destroyed
    /// only once the host frame they were dropped in has completed by that promise (and any
    /// submission of shine's own made before the drop), here or at a later call, or when the
    /// device goes. Neither waits nor submits. The host passes its own frame counter to every
    /// caller on the device; a number below the highest seen counts as the highest.
    pub fn begin_host_frame(&self, frame: u64, frames_in_flight: u32) {
        let ready = {
            let mut tracker = lock(&self.inner.tracker);
            // The clock never goes back: a lower number (a second caller counting from 0)
            // counts as the highest seen, so nothing is released early.
            let frame = tracker.host_frame.map_or(frame, |f| f.max(frame));
            tracker.host_frame = Some(frame);
            tracker.host_completed = frame.checked_sub(u64::from(frames_in_flight.max(1)));
            tracker.ready_host_garbage()
        };
        self.destroy_now(ready);
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
        let ready: Vec<Garbage> = ready
            .into_iter()
            .map(|(_, g)| g)
            .chain(tracker.ready_host_garbage())
            .collect();
        let (free, orphaned): (Vec<_>, Vec<_>) = tracker
            .orphaned
            .drain(..)
            .partition(|(serial, _)| *serial <= completed);
        tracker.orphaned = orphaned;
        tracker
            .free_contexts
            .extend(free.into_iter().map(|(_, c)| c));
        drop(tracker);
        self.destroy_now(ready);
        Ok(())
    }
}
