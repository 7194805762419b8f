//! GPU timing of passes: [`PassTiming`], and the timestamp scopes of one frame slot, which are
//! read back only once the frame recorded into them has completed.

use shine_gpu::{Device, TimestampPool};

/// Timestamp scopes one frame may hold (one per pass).
const SCOPES_PER_FRAME: u32 = 512;

/// GPU time of one executed pass.
#[derive(Clone, Debug, PartialEq)]
pub struct PassTiming {
    /// The pass name.
    pub name: String,
    /// Start in ns, relative to the first pass of the frame.
    pub begin_ns: f64,
    /// End in ns, same origin.
    pub end_ns: f64,
    /// The frame number.
    pub frame: u64,
    /// The pass's declared work ([`crate::PassBuilder::cost`]), if any.
    pub cost: Option<crate::PassCost>,
}

/// The timestamp scopes of one frame slot and the frame they hold until it is read.
pub(crate) struct SlotTimestamps {
    /// One scope per pass of the frame recorded with this slot.
    pub pool: TimestampPool,
    /// The frame recorded with this slot whose timings were not read yet.
    unread: Option<u64>,
    /// The declared work of each scope's pass, in the order the scopes were begun.
    costs: Vec<Option<crate::PassCost>>,
}

impl SlotTimestamps {
    /// Scopes for one frame, holding none yet.
    pub fn new(device: &Device) -> Result<Self, shine_gpu::Error> {
        Ok(Self {
            pool: TimestampPool::new(device, SCOPES_PER_FRAME)?,
            unread: None,
            costs: Vec::new(),
        })
    }

    /// Resets the scopes at the start of a frame's recording into `cb`.
    pub fn reset(&mut self, cb: shine_gpu::vk::CommandBuffer) {
        self.pool.reset(cb);
        self.costs.clear();
    }

    /// Opens the scope of pass `name`, whose declared work is `cost`.
    pub fn begin(
        &mut self,
        cb: shine_gpu::vk::CommandBuffer,
        name: &str,
        cost: Option<crate::PassCost>,
    ) -> Result<(), shine_gpu::Error> {
        self.pool.begin(cb, name)?;
        self.costs.push(cost);
        Ok(())
    }

    /// The scopes now hold `frame`'s passes, to be read by [`SlotTimestamps::take`].
    pub fn recorded(&mut self, frame: u64) {
        self.unread = Some(frame);
    }

    /// The frame whose timings wait to be read, if any.
    pub fn unread(&self) -> Option<u64> {
        self.unread
    }

    /// The pass timings of the unread frame, read without waiting: `None` while the GPU has
    /// not written them all (the frame is still in flight; it stays unread), an empty list when
    /// no frame is unread.
    pub fn try_take(&mut self) -> Result<Option<Vec<PassTiming>>, shine_gpu::Error> {
        let Some(frame) = self.unread else {
            return Ok(Some(Vec::new()));
        };
        let read = self.pool.try_read();
        if matches!(read, Ok(None)) {
            return Ok(None);
        }
        // Read (or unreadable): it counts as read either way.
        self.unread = None;
        let costs = &self.costs;
        Ok(read?.map(|timings| {
            timings
                .into_iter()
                .enumerate()
                .map(|(i, t)| PassTiming {
                    name: t.name,
                    begin_ns: t.begin_ns,
                    end_ns: t.end_ns,
                    frame,
                    cost: costs.get(i).copied().flatten(),
                })
                .collect()
        }))
    }

    /// The pass timings of the unread frame before the slot is recorded again (none when there
    /// is none), without waiting. That frame has completed (the [`crate::Executor`] contract);
    /// timings the GPU has not written are dropped rather than waited for. It counts as read
    /// afterwards, even when reading fails.
    pub fn take_before_reuse(&mut self) -> Result<Vec<PassTiming>, shine_gpu::Error> {
        let taken = self.try_take();
        self.unread = None;
        Ok(taken?.unwrap_or_default())
    }
}
