//! GPU timestamp scopes: a pair of timestamps around a named piece of work, read back in
//! nanoseconds after the submission completes. Honours `timestampValidBits` (ticks wrap at
//! that width) and `timestampPeriod` (nanoseconds per tick).

use crate::device::Device;
use crate::error::{Error, Result, VkContext};
use ash::vk;

/// Timing of one scope, in nanoseconds on the device's timestamp clock.
#[derive(Clone, Debug, PartialEq)]
pub struct ScopeTiming {
    /// Scope name (the pass name).
    pub name: String,
    /// Start, in ns since the first timestamp of the same pool (the start of the recording).
    pub begin_ns: f64,
    /// End, in the same time base.
    pub end_ns: f64,
}

impl ScopeTiming {
    /// Duration in nanoseconds.
    pub fn duration_ns(&self) -> f64 {
        self.end_ns - self.begin_ns
    }
}

/// Converts raw ticks to nanoseconds relative to `origin`, masking to the valid bits so a
/// counter that wrapped between `origin` and `ticks` still gives the right difference.
pub fn ticks_to_ns(ticks: u64, origin: u64, valid_bits: u32, period_ns: f32) -> f64 {
    let mask = if valid_bits >= 64 {
        u64::MAX
    } else {
        (1u64 << valid_bits) - 1
    };
    let delta = (ticks & mask).wrapping_sub(origin & mask) & mask;
    delta as f64 * f64::from(period_ns)
}

/// A query pool of `capacity` scopes (two queries each) with the names recorded into it.
pub struct TimestampPool {
    raw_device: ash::Device,
    _keep_alive: Option<Device>,
    pool: vk::QueryPool,
    capacity: u32,
    names: Vec<String>,
    open: Vec<u32>,
    valid_bits: u32,
    period_ns: f32,
}

impl TimestampPool {
    /// A pool for up to `capacity` scopes per recording.
    pub fn new(device: &Device, capacity: u32) -> Result<Self> {
        let mut pool = Self::detached(device, capacity)?;
        pool._keep_alive = Some(device.clone());
        Ok(pool)
    }

    /// A pool owned by one of the device's own command contexts (no keep-alive clone).
    pub(crate) fn detached(device: &Device, capacity: u32) -> Result<Self> {
        let info = vk::QueryPoolCreateInfo::default()
            .query_type(vk::QueryType::TIMESTAMP)
            .query_count(capacity.max(1) * 2);
        // SAFETY: valid create info on a live device.
        let pool = unsafe { device.raw().create_query_pool(&info, None) }
            .ctx("creating a timestamp query pool")?;
        Ok(Self {
            raw_device: device.raw().clone(),
            _keep_alive: None,
            pool,
            capacity: capacity.max(1),
            names: Vec::new(),
            open: Vec::new(),
            valid_bits: device.info().timestamp_valid_bits,
            period_ns: device.info().timestamp_period_ns,
        })
    }

    /// Resets every query; record this before the first scope of a command buffer.
    pub fn reset(&mut self, cb: vk::CommandBuffer) {
        // SAFETY: `cb` is recording, outside a render pass; the range lies in the pool.
        unsafe {
            self.raw_device
                .cmd_reset_query_pool(cb, self.pool, 0, self.capacity * 2)
        };
        self.names.clear();
        self.open.clear();
    }

    /// Writes the start timestamp of a scope.
    pub fn begin(&mut self, cb: vk::CommandBuffer, name: &str) -> Result<()> {
        let index = self.names.len() as u32;
        if index >= self.capacity {
            return Err(Error::InvalidUsage(format!(
                "more than {} timestamp scopes in one recording (at `{name}`)",
                self.capacity
            )));
        }
        self.names.push(name.to_string());
        self.open.push(index);
        // SAFETY: the query was reset in this command buffer and is written once.
        unsafe {
            self.raw_device.cmd_write_timestamp2(
                cb,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                index * 2,
            )
        };
        Ok(())
    }

    /// Writes the end timestamp of the innermost open scope.
    pub fn end(&mut self, cb: vk::CommandBuffer) -> Result<()> {
        let index = self
            .open
            .pop()
            .ok_or_else(|| Error::InvalidUsage("timestamp scope ended but none is open".into()))?;
        // SAFETY: as in `begin`.
        unsafe {
            self.raw_device.cmd_write_timestamp2(
                cb,
                vk::PipelineStageFlags2::ALL_COMMANDS,
                self.pool,
                index * 2 + 1,
            )
        };
        Ok(())
    }

    /// Reads every closed scope, waiting for the GPU to write them. Call only after the
    /// submission has completed.
    pub fn read(&self) -> Result<Vec<ScopeTiming>> {
        self.read_with(vk::QueryResultFlags::WAIT)
            .map(Option::unwrap_or_default)
    }

    /// Reads every closed scope without waiting: `None` when the GPU has not written all of
    /// them yet (their work is still in flight). For readers on a host's record path, which
    /// must never block.
    pub fn try_read(&self) -> Result<Option<Vec<ScopeTiming>>> {
        self.read_with(vk::QueryResultFlags::empty())
    }

    fn read_with(&self, wait: vk::QueryResultFlags) -> Result<Option<Vec<ScopeTiming>>> {
        if !self.open.is_empty() {
            return Err(Error::InvalidUsage(format!(
                "{} timestamp scope(s) were never ended",
                self.open.len()
            )));
        }
        let count = self.names.len();
        if count == 0 {
            return Ok(Some(Vec::new()));
        }
        let mut ticks = vec![0u64; count * 2];
        // SAFETY: every query in the range was reset and written by a submitted recording.
        let read = unsafe {
            self.raw_device.get_query_pool_results(
                self.pool,
                0,
                &mut ticks,
                vk::QueryResultFlags::TYPE_64 | wait,
            )
        };
        match read {
            Ok(()) => {}
            Err(vk::Result::NOT_READY) if wait.is_empty() => return Ok(None),
            Err(e) => return Err(Error::vk("reading timestamps", e)),
        }
        let origin = ticks[0];
        Ok(Some(
            self.names
                .iter()
                .enumerate()
                .map(|(i, name)| ScopeTiming {
                    name: name.clone(),
                    begin_ns: ticks_to_ns(ticks[2 * i], origin, self.valid_bits, self.period_ns),
                    end_ns: ticks_to_ns(ticks[2 * i + 1], origin, self.valid_bits, self.period_ns),
                })
                .collect(),
        ))
    }
}

impl Drop for TimestampPool {
    fn drop(&mut self) {
        match &self._keep_alive {
            // Destroyed once the frames that wrote it have completed.
            Some(device) => device.defer(crate::retire::Garbage::QueryPool(self.pool)),
            // SAFETY: inside the device's own command contexts, destroyed after their
            // submissions completed.
            None => unsafe { self.raw_device.destroy_query_pool(self.pool, None) },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::ticks_to_ns;

    #[test]
    fn ticks_convert_with_period() {
        assert_eq!(ticks_to_ns(1_500, 500, 64, 2.0), 2_000.0);
    }

    #[test]
    fn ticks_wrap_at_valid_bits() {
        // A 36-bit counter that wrapped: origin near the top, value just past zero.
        let top = (1u64 << 36) - 10;
        assert_eq!(ticks_to_ns(5, top, 36, 1.0), 15.0);
        // Garbage above the valid bits is ignored.
        assert_eq!(ticks_to_ns((1u64 << 40) | 20, 10, 36, 1.0), 10.0);
    }
}
