//! Execution: compile (cached), create or reuse the graph's own resources, and record every pass
//! with its barriers, a debug label and a GPU timestamp scope into the caller's command buffer.
//!
//! [`Executor`] drives a frame; the pieces it drives live beside it: the objects it keeps across
//! frames in `objects`, its pipelines in `pipelines`, the recording of a pass in `record` and
//! the reading of timestamps in `timing`.

use std::sync::Arc;

use shine_gpu::{DescriptorArena, Device, vk};

use crate::compiler::Compiler;
use crate::error::ExecuteError;
use crate::gpu_resources::DeviceMemory;
use crate::graph::RenderGraph;
use crate::objects::GraphObjects;
use crate::pipelines::PipelineCache;
use crate::plan::Plan;
use crate::record::{Recorder, check_area};
use crate::timing::{PassTiming, SlotTimestamps};
use crate::work::Work;

/// Per-slot recording state: descriptor sets and timestamps of one frame in flight.
struct FrameSlot {
    /// Descriptor sets of the slot's frame, reset when the slot is reused.
    descriptors: DescriptorArena,
    /// One timestamp scope per pass of the slot's frame.
    timestamps: SlotTimestamps,
}

/// Runs render graphs on a device, frame after frame.
///
/// The caller owns the command buffers and their submission (so a host engine can embed the
/// graph). Contract: before `execute` records frame `f`, the submission of frame
/// `f - frames_in_flight` has completed; [`Executor::timings`] reports only frames that have
/// completed (it never waits). Frame `f` records with slot `f % frames_in_flight`: its own transient
/// resources, descriptor sets and timestamps, so frames in flight share none of them.
pub struct Executor {
    device: Device,
    compiler: Compiler,
    /// One per frame in flight: frame `f` uses `slots[f % slots.len()]`.
    slots: Vec<FrameSlot>,
    /// The number of the next frame.
    frame: u64,
    pipelines: PipelineCache,
    objects: GraphObjects,
    /// Timings read from a slot before its reuse, not returned by [`Executor::timings`] yet.
    timings: Vec<PassTiming>,
}

impl std::fmt::Debug for Executor {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Executor")
            .field("frame", &self.frame)
            .field("frames_in_flight", &self.slots.len())
            .finish_non_exhaustive()
    }
}

impl Executor {
    /// An executor for `device` with `frames_in_flight` (at least 1) recordings in flight.
    pub fn new(device: &Device, frames_in_flight: usize) -> Result<Self, ExecuteError> {
        let slots = (0..frames_in_flight.max(1))
            .map(|_| {
                Ok(FrameSlot {
                    descriptors: DescriptorArena::new(device),
                    timestamps: SlotTimestamps::new(device)?,
                })
            })
            .collect::<Result<Vec<_>, shine_gpu::Error>>()?;
        Ok(Self {
            device: device.clone(),
            compiler: Compiler::new(),
            slots,
            frame: 0,
            pipelines: PipelineCache::default(),
            objects: GraphObjects::default(),
            timings: Vec::new(),
        })
    }

    /// An empty graph for the next frame.
    pub fn begin_frame(&self) -> RenderGraph {
        RenderGraph::in_flight(self.frame, self.slots.len())
    }

    /// The number of the next frame.
    pub fn frame(&self) -> u64 {
        self.frame
    }

    /// Numbers the next frame `frame`, which must not be below [`Executor::frame`]: a shard of
    /// a sequence starts at its own frame number, so that what is keyed by the frame number
    /// (jitter sequences, amortised slices, history ping-pong) matches a one-process run.
    /// Call with no frame in flight. Returns whether the number was taken (false: `frame` lies
    /// behind the next frame, nothing changed).
    pub fn skip_to_frame(&mut self, frame: u64) -> bool {
        let forward = frame >= self.frame;
        if forward {
            self.frame = frame;
        }
        forward
    }

    /// Device memory the executor holds: `(transients, temporal)` bytes: the aliased heaps of
    /// every kept transient set (one per frame slot and transient layout) and the temporal and history
    /// resources kept across frames.
    pub fn memory(&self) -> (u64, u64) {
        self.objects.memory()
    }

    /// The compiler (plan cache and temporal history).
    pub fn compiler(&self) -> &Compiler {
        &self.compiler
    }

    /// Compiles `graph` (cached while its shape is unchanged) and records it into `cb`, which
    /// must be recording outside a render pass. Returns the plan it ran.
    ///
    /// Compilation, resource creation and pipeline creation happen before anything is recorded:
    /// an error from them leaves `cb` untouched. An error while recording (a raw pass's, a
    /// binding or push-constant mismatch) leaves every debug label and timestamp scope closed
    /// but the frame half recorded: don't submit `cb` after any error, and the frame is not
    /// counted.
    pub fn execute(
        &mut self,
        cb: vk::CommandBuffer,
        graph: RenderGraph,
    ) -> Result<Arc<Plan>, ExecuteError> {
        self.run(graph, Some(cb)).map(|(plan, _)| plan)
    }

    /// Compiles and runs `graph` one pass at a time: each pass (with its barriers) is recorded
    /// into its own command buffer, submitted and waited for, and timed on the host from submit
    /// to completion. Returns the plan and the host times of its passes (origin: the first
    /// submit).
    ///
    /// For devices whose timestamps do not bracket the work of a pass (lavapipe writes them when
    /// it flushes rasterisation, not when a compute dispatch runs): the times are exact up to a
    /// submission's overhead (tens of µs), at the cost of serialising the frame.
    pub fn execute_serialized(
        &mut self,
        graph: RenderGraph,
    ) -> Result<(Arc<Plan>, Vec<PassTiming>), ExecuteError> {
        self.run(graph, None)
    }

    /// [`Executor::execute`] into `cb`, or [`Executor::execute_serialized`] when `cb` is `None`.
    fn run(
        &mut self,
        mut graph: RenderGraph,
        cb: Option<vk::CommandBuffer>,
    ) -> Result<(Arc<Plan>, Vec<PassTiming>), ExecuteError> {
        let plan = self.compiler.compile(&graph, &DeviceMemory(&self.device))?;
        let slot_index = (self.frame % self.slots.len() as u64) as usize;
        let set = self
            .objects
            .transients_for(&self.device, &plan, slot_index, self.slots.len())?;
        self.objects.ensure_temporal(&self.device, &plan)?;
        for pass in &plan.passes {
            match &graph.works[pass.id.0 as usize] {
                Work::Compute(c) => {
                    self.pipelines.compute(&self.device, c.shader)?;
                }
                Work::Raster(r) => {
                    check_area(&plan, pass, r)?;
                    self.pipelines.graphics(&self.device, &r.pipeline)?;
                }
                Work::Declared | Work::Transfer(_) | Work::Raw(_) => {}
            }
        }

        let objects = self.objects.table(&plan, set, &graph.externals)?;

        let slot = &mut self.slots[slot_index];
        // The slot's previous frame has completed (the contract); its timings are read without
        // waiting.
        self.timings.extend(slot.timestamps.take_before_reuse()?);
        slot.descriptors.reset()?;
        if let Some(cb) = cb {
            slot.timestamps.reset(cb);
        }
        let mut host_timings = Vec::new();
        let start = std::time::Instant::now();
        for (position, pass) in plan.passes.iter().enumerate() {
            // Serialized: a command buffer of its own for this pass.
            let (own, pass_cb) = match cb {
                Some(cb) => (None, cb),
                None => {
                    let mut commands = self.device.begin_commands()?;
                    let raw = commands.raw();
                    (Some(commands), raw)
                }
            };
            let recorder = Recorder::new(&self.device, pass_cb, &plan, &objects);
            recorder.barriers(&pass.barriers);
            if cb.is_some() {
                slot.timestamps.begin(pass_cb, &pass.name, pass.cost)?;
            }
            self.device.begin_label(pass_cb, &pass.name);
            let work = std::mem::replace(&mut graph.works[pass.id.0 as usize], Work::Declared);
            // The pipelines were created above; an error here still closes the scopes.
            let recorded = recorder.work(
                pass,
                position,
                work,
                &mut self.pipelines,
                &mut slot.descriptors,
            );
            self.device.end_label(pass_cb);
            if cb.is_some() {
                slot.timestamps.pool.end(pass_cb)?;
            }
            recorded?;
            if let Some(commands) = own {
                let begin_ns = start.elapsed().as_secs_f64() * 1e9;
                self.device.submit(commands)?.wait()?;
                host_timings.push(PassTiming {
                    name: pass.name.clone(),
                    begin_ns,
                    end_ns: start.elapsed().as_secs_f64() * 1e9,
                    frame: self.frame,
                    cost: pass.cost,
                });
            }
        }
        match cb {
            Some(cb) => {
                Recorder::new(&self.device, cb, &plan, &objects).barriers(&plan.final_barriers);
                slot.timestamps.recorded(self.frame);
            }
            None => {
                let mut commands = self.device.begin_commands()?;
                Recorder::new(&self.device, commands.raw(), &plan, &objects)
                    .barriers(&plan.final_barriers);
                self.device.submit(commands)?.wait()?;
            }
        }
        self.compiler.finish_frame(&plan);
        self.frame += 1;
        Ok((plan, host_timings))
    }

    /// Per-pass GPU times of every executed frame not reported yet whose timestamps the GPU
    /// has written, oldest first; never waits (a frame still in flight is reported by a later
    /// call).
    pub fn timings(&mut self) -> Result<Vec<PassTiming>, ExecuteError> {
        let mut unread: Vec<&mut SlotTimestamps> = self
            .slots
            .iter_mut()
            .map(|s| &mut s.timestamps)
            .filter(|t| t.unread().is_some())
            .collect();
        unread.sort_by_key(|t| t.unread());
        for timestamps in unread {
            match timestamps.try_take()? {
                Some(timings) => self.timings.extend(timings),
                // Keep frames in order: the later ones wait for this one.
                None => break,
            }
        }
        Ok(std::mem::take(&mut self.timings))
    }
}

impl Drop for Executor {
    fn drop(&mut self) {
        // Nothing waits: the objects, their memory blocks, descriptor pools and query pools are
        // destroyed by the device once the frames that used them have completed (its own
        // submissions, and the host frames of `Device::begin_host_frame`).
        self.objects.destroy(&self.device);
    }
}
