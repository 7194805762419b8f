//! Command recording and submission. A [`Commands`] is a primary command buffer with its own
//! descriptor arena and timestamp pool; [`Device::submit`] sends it with a fence and returns a
//! [`Submission`] to wait on, which yields the timestamp scopes recorded into it.

use crate::descriptors::{Descriptor, DescriptorArena};
use crate::device::{Device, lock};
use crate::error::{Error, Result, VkContext};
use crate::pipeline::{ComputePipeline, GraphicsPipeline, PipelineLayout};
use crate::timestamps::{ScopeTiming, TimestampPool};
use ash::vk;

/// Timestamp scopes one recording may hold.
pub const SCOPES_PER_RECORDING: u32 = 256;

/// Everything one recording needs, recycled once its submission completes.
pub(crate) struct Context {
    pool: vk::CommandPool,
    cb: vk::CommandBuffer,
    fence: vk::Fence,
    descriptors: DescriptorArena,
    timestamps: TimestampPool,
}

impl Context {
    fn new(device: &Device) -> Result<Self> {
        let raw = device.raw();
        let info = vk::CommandPoolCreateInfo::default()
            .flags(vk::CommandPoolCreateFlags::TRANSIENT)
            .queue_family_index(device.queue_family());
        // SAFETY: valid create info on a live device.
        let pool =
            unsafe { raw.create_command_pool(&info, None) }.ctx("creating a command pool")?;
        let destroy_pool = || {
            // SAFETY: nothing allocated from it is in use.
            unsafe { raw.destroy_command_pool(pool, None) }
        };
        let alloc = vk::CommandBufferAllocateInfo::default()
            .command_pool(pool)
            .level(vk::CommandBufferLevel::PRIMARY)
            .command_buffer_count(1);
        // SAFETY: the pool belongs to this device.
        let cb = match unsafe { raw.allocate_command_buffers(&alloc) } {
            Ok(cbs) => cbs.first().copied().unwrap_or_default(),
            Err(e) => {
                destroy_pool();
                return Err(Error::vk("allocating a command buffer", e));
            }
        };
        // SAFETY: valid create info on a live device.
        let fence = match unsafe { raw.create_fence(&vk::FenceCreateInfo::default(), None) } {
            Ok(f) => f,
            Err(e) => {
                destroy_pool();
                return Err(Error::vk("creating a fence", e));
            }
        };
        let timestamps = match TimestampPool::detached(device, SCOPES_PER_RECORDING) {
            Ok(t) => t,
            Err(e) => {
                // SAFETY: never used.
                unsafe { raw.destroy_fence(fence, None) };
                destroy_pool();
                return Err(e);
            }
        };
        Ok(Self {
            pool,
            cb,
            fence,
            descriptors: DescriptorArena::detached(raw),
            timestamps,
        })
    }

    /// Destroys the context; its submission must have completed.
    pub(crate) fn destroy(self, device: &ash::Device) {
        // SAFETY: the GPU is done with everything recorded from this context.
        unsafe {
            device.destroy_fence(self.fence, None);
            device.destroy_command_pool(self.pool, None);
        }
        drop(self.descriptors);
        drop(self.timestamps);
    }
}

/// A command buffer being recorded.
pub struct Commands {
    device: Device,
    context: Option<Context>,
}

impl Device {
    /// Starts recording a command buffer (one-time submit).
    pub fn begin_commands(&self) -> Result<Commands> {
        self.retire()?;
        let recycled = lock(&self.inner.tracker).free_contexts.pop();
        let mut context = match recycled {
            Some(c) => c,
            None => Context::new(self)?,
        };
        let raw = self.raw();
        let prepared = (|| {
            // SAFETY: the context's previous submission completed (it was recycled).
            unsafe {
                raw.reset_command_pool(context.pool, vk::CommandPoolResetFlags::empty())
                    .ctx("resetting a command pool")?;
                raw.reset_fences(&[context.fence])
                    .ctx("resetting a fence")?;
            }
            context.descriptors.reset()?;
            let begin = vk::CommandBufferBeginInfo::default()
                .flags(vk::CommandBufferUsageFlags::ONE_TIME_SUBMIT);
            // SAFETY: the command buffer was reset with its pool.
            unsafe { raw.begin_command_buffer(context.cb, &begin) }
                .ctx("beginning a command buffer")?;
            context.timestamps.reset(context.cb);
            Ok::<(), Error>(())
        })();
        if let Err(e) = prepared {
            // Its previous submission has completed: keep it for the next attempt.
            lock(&self.inner.tracker).free_contexts.push(context);
            return Err(e);
        }
        lock(&self.inner.tracker).recording += 1;
        Ok(Commands {
            device: self.clone(),
            context: Some(context),
        })
    }

    /// Ends and submits a recording. The returned [`Submission`] may be waited on or dropped.
    pub fn submit(&self, mut commands: Commands) -> Result<Submission> {
        let Some(context) = commands.context.take() else {
            return Err(Error::InvalidUsage(
                "commands were already submitted".into(),
            ));
        };
        let raw = self.raw();
        let mut tracker = lock(&self.inner.tracker);
        // SAFETY: the command buffer is recording.
        if let Err(e) = unsafe { raw.end_command_buffer(context.cb) } {
            tracker.free_contexts.push(context);
            tracker.recording_closed();
            return Err(Error::vk("ending a command buffer", e));
        }
        let cb_info = [vk::CommandBufferSubmitInfo::default().command_buffer(context.cb)];
        let submit = [vk::SubmitInfo2::default().command_buffer_infos(&cb_info)];
        let result = {
            let queue = lock(&self.inner.queue);
            // SAFETY: the queue is externally synchronised by its lock; the fence is unsignalled.
            unsafe { raw.queue_submit2(*queue, &submit, context.fence) }
        };
        if let Err(e) = result {
            // The fence never got a signal operation: wait for the queue before reuse.
            tracker.recording_closed();
            drop(tracker);
            let _ = self.wait_idle();
            lock(&self.inner.tracker).free_contexts.push(context);
            return Err(Error::vk("submitting commands", e));
        }
        tracker.submitted += 1;
        let serial = tracker.submitted;
        tracker.in_flight.push_back((serial, context.fence));
        tracker.recording_closed();
        drop(tracker);
        Ok(Submission {
            device: self.clone(),
            context: Some(context),
            serial,
        })
    }

    /// Records with `record`, submits and waits: for uploads, readbacks and tests.
    pub fn run_once(
        &self,
        record: impl FnOnce(&mut Commands) -> Result<()>,
    ) -> Result<Vec<ScopeTiming>> {
        let mut commands = self.begin_commands()?;
        record(&mut commands)?;
        self.submit(commands)?.wait()
    }
}

impl Commands {
    fn context(&mut self) -> &mut Context {
        match self.context.as_mut() {
            Some(c) => c,
            // `context` is only taken by `Device::submit`, which consumes `self`.
            None => unreachable!("Commands used after submission"),
        }
    }

    /// The command buffer, for recording what shine-gpu has no helper for.
    pub fn raw(&mut self) -> vk::CommandBuffer {
        self.context().cb
    }

    /// The device this recording belongs to.
    pub fn device(&self) -> &Device {
        &self.device
    }

    /// Opens a named timestamp scope and debug label (nestable).
    pub fn begin_scope(&mut self, name: &str) -> Result<()> {
        let device = self.device.clone();
        let context = self.context();
        context.timestamps.begin(context.cb, name)?;
        device.begin_label(context.cb, name);
        Ok(())
    }

    /// Closes the innermost scope.
    pub fn end_scope(&mut self) -> Result<()> {
        let device = self.device.clone();
        let context = self.context();
        context.timestamps.end(context.cb)?;
        device.end_label(context.cb);
        Ok(())
    }

    /// Binds a compute pipeline and its resources (matched to reflected bindings by name).
    pub fn bind_compute(
        &mut self,
        pipeline: &ComputePipeline,
        resources: &[(&str, Descriptor)],
    ) -> Result<()> {
        let raw = self.device.raw().clone();
        let context = self.context();
        // SAFETY: `cb` is recording; the pipeline belongs to this device.
        unsafe {
            raw.cmd_bind_pipeline(context.cb, vk::PipelineBindPoint::COMPUTE, pipeline.raw())
        };
        context.descriptors.bind(
            context.cb,
            vk::PipelineBindPoint::COMPUTE,
            pipeline.layout(),
            resources,
        )
    }

    /// Binds a graphics pipeline and its resources.
    pub fn bind_graphics(
        &mut self,
        pipeline: &GraphicsPipeline,
        resources: &[(&str, Descriptor)],
    ) -> Result<()> {
        let raw = self.device.raw().clone();
        let context = self.context();
        // SAFETY: `cb` is recording; the pipeline belongs to this device.
        unsafe {
            raw.cmd_bind_pipeline(context.cb, vk::PipelineBindPoint::GRAPHICS, pipeline.raw())
        };
        context.descriptors.bind(
            context.cb,
            vk::PipelineBindPoint::GRAPHICS,
            pipeline.layout(),
            resources,
        )
    }

    /// Pushes constants; `data` must be exactly the reflected push-constant size.
    pub fn push_constants(&mut self, layout: &PipelineLayout, data: &[u8]) -> Result<()> {
        let (size, stages) = layout.push_constants;
        if data.len() != size as usize {
            return Err(Error::Binding {
                pipeline: layout.name.clone(),
                message: format!(
                    "push constants are {size} bytes in the shader, {} given",
                    data.len()
                ),
            });
        }
        if size == 0 {
            return Ok(());
        }
        let raw = self.device.raw().clone();
        let cb = self.raw();
        // SAFETY: the range matches the layout's push-constant range.
        unsafe { raw.cmd_push_constants(cb, layout.raw, stages, 0, data) };
        Ok(())
    }

    /// Dispatches enough workgroups to cover `threads` invocations of the bound pipeline.
    pub fn dispatch_threads(&mut self, pipeline: &ComputePipeline, threads: [u32; 3]) {
        let [x, y, z] = pipeline.shader().groups_for(threads);
        let raw = self.device.raw().clone();
        let cb = self.raw();
        // SAFETY: `cb` is recording with a compute pipeline bound.
        unsafe { raw.cmd_dispatch(cb, x, y, z) };
    }

    /// Copies buffer regions (the caller orders it against other work with barriers).
    pub fn copy_buffer(&mut self, src: vk::Buffer, dst: vk::Buffer, regions: &[vk::BufferCopy]) {
        let raw = self.device.raw().clone();
        let cb = self.raw();
        // SAFETY: `cb` is recording; the caller passes live buffers and in-bounds regions.
        unsafe { raw.cmd_copy_buffer(cb, src, dst, regions) };
    }

    /// Records a synchronization2 dependency.
    pub fn barrier(&mut self, dependency: &vk::DependencyInfo<'_>) {
        let raw = self.device.raw().clone();
        let cb = self.raw();
        // SAFETY: `cb` is recording; the dependency's resources belong to this device.
        unsafe { raw.cmd_pipeline_barrier2(cb, dependency) };
    }

    /// A global memory dependency between two stage/access scopes.
    pub fn memory_barrier(
        &mut self,
        src: (vk::PipelineStageFlags2, vk::AccessFlags2),
        dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    ) {
        let barriers = [vk::MemoryBarrier2::default()
            .src_stage_mask(src.0)
            .src_access_mask(src.1)
            .dst_stage_mask(dst.0)
            .dst_access_mask(dst.1)];
        self.barrier(&vk::DependencyInfo::default().memory_barriers(&barriers));
    }

    /// Transitions a whole image between layouts with the given scopes.
    pub fn image_barrier(
        &mut self,
        image: vk::Image,
        range: vk::ImageSubresourceRange,
        layouts: (vk::ImageLayout, vk::ImageLayout),
        src: (vk::PipelineStageFlags2, vk::AccessFlags2),
        dst: (vk::PipelineStageFlags2, vk::AccessFlags2),
    ) {
        let barriers = [vk::ImageMemoryBarrier2::default()
            .image(image)
            .subresource_range(range)
            .old_layout(layouts.0)
            .new_layout(layouts.1)
            .src_stage_mask(src.0)
            .src_access_mask(src.1)
            .dst_stage_mask(dst.0)
            .dst_access_mask(dst.1)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)];
        self.barrier(&vk::DependencyInfo::default().image_memory_barriers(&barriers));
    }
}

impl Drop for Commands {
    fn drop(&mut self) {
        // Abandoned without submitting: nothing of it reached the GPU.
        if let Some(context) = self.context.take() {
            let mut tracker = lock(&self.device.inner.tracker);
            tracker.free_contexts.push(context);
            tracker.recording_closed();
        }
    }
}

/// A submitted recording. Wait on it for its timestamp scopes, or drop it: its resources are
/// recycled once its fence signals.
pub struct Submission {
    device: Device,
    context: Option<Context>,
    serial: u64,
}

impl Submission {
    /// The submission serial (increasing per device).
    pub fn serial(&self) -> u64 {
        self.serial
    }

    /// Waits for completion and returns the timestamp scopes recorded.
    pub fn wait(mut self) -> Result<Vec<ScopeTiming>> {
        let Some(context) = self.context.take() else {
            return Ok(Vec::new());
        };
        let raw = self.device.raw();
        // SAFETY: the fence belongs to this device and was submitted.
        let waited = unsafe { raw.wait_for_fences(&[context.fence], true, u64::MAX) };
        if let Err(e) = waited {
            lock(&self.device.inner.tracker)
                .orphaned
                .push((self.serial, context));
            return Err(Error::vk("waiting for a submission", e));
        }
        let timings = context.timestamps.read();
        // Retire first: it removes this submission's fence from the in-flight list (fences of
        // one queue signal in submission order), so the context may be reused.
        match self.device.retire() {
            Ok(()) => lock(&self.device.inner.tracker).free_contexts.push(context),
            Err(e) => {
                lock(&self.device.inner.tracker)
                    .orphaned
                    .push((self.serial, context));
                return Err(e);
            }
        }
        timings
    }
}

impl Drop for Submission {
    fn drop(&mut self) {
        if let Some(context) = self.context.take() {
            lock(&self.device.inner.tracker)
                .orphaned
                .push((self.serial, context));
        }
    }
}

impl Device {
    /// Opens a debug-utils label (shown by RenderDoc and Nsight); a no-op without debug utils.
    pub fn begin_label(&self, cb: vk::CommandBuffer, name: &str) {
        let Some(debug) = &self.inner.debug_utils else {
            return;
        };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let label = vk::DebugUtilsLabelEXT::default().label_name(&name);
        // SAFETY: `cb` is recording on this device.
        unsafe { debug.cmd_begin_debug_utils_label(cb, &label) };
    }

    /// Closes the innermost debug-utils label.
    pub fn end_label(&self, cb: vk::CommandBuffer) {
        if let Some(debug) = &self.inner.debug_utils {
            // SAFETY: `cb` is recording on this device with a label open.
            unsafe { debug.cmd_end_debug_utils_label(cb) };
        }
    }
}
