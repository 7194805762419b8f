//! The executor embedded in a host's frame loop, on a real device (lavapipe in CI) with the
//! validation layer when installed: the host records into its own command buffers, submits
//! them itself with two frames in flight and runs the device's host frame clock. Plans change
//! every frame, so transient sets are evicted and temporal resources recreated while frames
//! are in flight; nothing may be destroyed while the GPU can still use it (the validation layer
//! reports that), and nothing on the record path waits.

use shine_gpu::{Device, DeviceDesc, MemoryLocation, Validation, vk};
use shine_graph::{BufferAccess, BufferDesc, Executor, ExternalState, RenderGraph};

const FRAMES: u64 = 20;
const IN_FLIGHT: usize = 2;

fn device() -> Device {
    let validation = if std::env::var_os("CI").is_some() {
        Validation::Required
    } else {
        Validation::IfAvailable
    };
    Device::new(&DeviceDesc {
        validation,
        ..DeviceDesc::from_env()
    })
    .unwrap_or_else(|e| panic!("GPU tests need a Vulkan 1.3 device: {e}"))
}

/// The host's per-frame objects: a command buffer and its fence per frame in flight.
struct HostFrames {
    device: Device,
    pool: vk::CommandPool,
    cbs: Vec<vk::CommandBuffer>,
    fences: Vec<vk::Fence>,
    queue: vk::Queue,
}

impl HostFrames {
    fn new(device: &Device) -> Self {
        let raw = device.raw();
        // SAFETY: test code: valid create infos on a live device, destroyed in Drop. The queue
        // is the one shine submits to; this test never submits from two threads.
        unsafe {
            let pool = raw
                .create_command_pool(
                    &vk::CommandPoolCreateInfo::default()
                        .flags(vk::CommandPoolCreateFlags::RESET_COMMAND_BUFFER)
                        .queue_family_index(device.queue_family()),
                    None,
                )
                .unwrap();
            let cbs = raw
                .allocate_command_buffers(
                    &vk::CommandBufferAllocateInfo::default()
                        .command_pool(pool)
                        .level(vk::CommandBufferLevel::PRIMARY)
                        .command_buffer_count(IN_FLIGHT as u32),
                )
                .unwrap();
            let fences = (0..IN_FLIGHT)
                .map(|_| {
                    raw.create_fence(
                        &vk::FenceCreateInfo::default().flags(vk::FenceCreateFlags::SIGNALED),
                        None,
                    )
                    .unwrap()
                })
                .collect();
            Self {
                device: device.clone(),
                pool,
                cbs,
                fences,
                queue: raw.get_device_queue(device.queue_family(), 0),
            }
        }
    }

    /// Waits for the frame that last used `slot`, as a host does before reusing it.
    fn wait(&self, slot: usize) {
        // SAFETY: the fence belongs to this device.
        unsafe {
            self.device
                .raw()
                .wait_for_fences(&[self.fences[slot]], true, u64::MAX)
                .unwrap()
        };
    }

    fn record_and_submit(&self, slot: usize, record: impl FnOnce(vk::CommandBuffer)) {
        let raw = self.device.raw();
        let cb = self.cbs[slot];
        // SAFETY: the slot's previous submission completed (`wait`); one thread submits.
        unsafe {
            raw.reset_fences(&[self.fences[slot]]).unwrap();
            raw.reset_command_buffer(cb, vk::CommandBufferResetFlags::empty())
                .unwrap();
            raw.begin_command_buffer(cb, &vk::CommandBufferBeginInfo::default())
                .unwrap();
            record(cb);
            raw.end_command_buffer(cb).unwrap();
            let cbs = [cb];
            raw.queue_submit(
                self.queue,
                &[vk::SubmitInfo::default().command_buffers(&cbs)],
                self.fences[slot],
            )
            .unwrap();
        }
    }
}

impl Drop for HostFrames {
    fn drop(&mut self) {
        let raw = self.device.raw();
        // SAFETY: every submission completed (waited for below); created in `new`.
        unsafe {
            let _ = raw.wait_for_fences(&self.fences, true, u64::MAX);
            for &f in &self.fences {
                raw.destroy_fence(f, None);
            }
            raw.destroy_command_pool(self.pool, None);
        }
    }
}

/// Frame `frame`: a transient and a temporal buffer whose sizes change every frame (a new plan,
/// new transients, a recreated temporal), filled with `frame + 1`; 16 bytes of it land in
/// `readback`.
fn graph(executor: &Executor, readback: &shine_gpu::Buffer) -> RenderGraph {
    let frame = executor.frame();
    let size = 256 * (frame + 1);
    let mut rg = executor.begin_frame();
    let mut scratch = rg.create_buffer("scratch", BufferDesc::new(size));
    let mut history = rg.temporal_buffer("history", BufferDesc::new(size));
    let read_by_copy = ExternalState::new(
        vk::PipelineStageFlags2::COPY,
        vk::AccessFlags2::TRANSFER_READ,
        vk::ImageLayout::UNDEFINED,
    );
    let mut out = rg.import_gpu_buffer(readback, ExternalState::UNDEFINED, read_by_copy);
    rg.fill_buffer("fill", &mut scratch, frame as u32 + 1);
    rg.copy_buffer("keep", &scratch, &mut history);
    let (src, dst) = (history, out);
    rg.raw_pass("copy_out", move |ctx| {
        if let (Some(src), Some(dst)) = (ctx.buffer(&src), ctx.buffer(&dst)) {
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size: 16,
            };
            // SAFETY: both buffers live for the frame; the graph put them in copy scope.
            unsafe {
                ctx.device
                    .raw()
                    .cmd_copy_buffer(ctx.cb, src, dst, &[region])
            };
        }
        Ok(())
    })
    .read(&history, BufferAccess::CopySrc)
    .write(&mut out, BufferAccess::CopyDst);
    rg
}

#[test]
fn an_embedded_executor_frees_nothing_a_host_frame_in_flight_uses() {
    let device = device();
    let readbacks: Vec<_> = (0..IN_FLIGHT)
        .map(|i| {
            shine_gpu::Buffer::new(
                &device,
                &shine_gpu::BufferDesc {
                    name: &format!("readback {i}"),
                    size: 16,
                    usage: vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST,
                    location: MemoryLocation::GpuOnly,
                },
            )
            .unwrap()
        })
        .collect();
    let baseline = device.memory_usage();
    let host = HostFrames::new(&device);
    let mut executor = Executor::new(&device, IN_FLIGHT).unwrap();
    for frame in 0..FRAMES {
        let slot = frame as usize % IN_FLIGHT;
        host.wait(slot);
        device.begin_host_frame(frame, IN_FLIGHT as u32);
        let graph = graph(&executor, &readbacks[slot]);
        host.record_and_submit(slot, |cb| {
            executor.execute(cb, graph).unwrap();
        });
    }
    assert_eq!(executor.compiler().compilations(), FRAMES);
    // Frames 18 and 19 may still be in flight: dropping the executor must not wait for them,
    // nor destroy what they use.
    drop(executor);
    assert!(
        device.pending_destructions() > 0,
        "destroyed while in flight"
    );
    host.wait(0);
    host.wait(1);
    for (slot, frame) in [(0, FRAMES - 2), (1, FRAMES - 1)] {
        let bytes = device.read_buffer(&readbacks[slot]).unwrap();
        assert_eq!(
            bytes[..4],
            (frame as u32 + 1).to_le_bytes(),
            "frame {frame}"
        );
    }
    // The host's next frames: everything the executor held has completed.
    device.begin_host_frame(FRAMES, IN_FLIGHT as u32);
    device.begin_host_frame(FRAMES + 1, IN_FLIGHT as u32);
    assert_eq!(device.pending_destructions(), 0);
    assert_eq!(device.memory_usage().allocations, baseline.allocations);
    assert_eq!(
        device.memory_usage().allocated_bytes,
        baseline.allocated_bytes
    );
    drop(host);
    let counts = device.message_counts();
    assert_eq!(counts.problems(), 0, "{}", device.messages().join("\n"));
}
