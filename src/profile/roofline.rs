//! `shine profile --roofline`: how close each pass runs to the machine's limits.
//!
//! Two micro-kernels measure the device's limits once: `shaders/roofline_fma.comp` its fp32
//! multiply-add peak (GFLOP/s), `shaders/roofline_copy.comp` its memory bandwidth (GB/s, a copy
//! between buffers far larger than any cache). Each is run until one submission lasts at least
//! [`MIN_RUN_S`], then [`RUNS`] times, and the fastest run counts; the host clock brackets
//! submit-to-completion, which also works on CPU devices whose timestamps miss compute work.
//! [`Peaks`] are cached per device and driver ([`cache_dir`]), so later profiles start at once.
//!
//! Passes declare their work ([`PassCost`], a formula beside each pass), and the report divides
//! it by the time the pass took over the measured frames: achieved GFLOP/s and GB/s, their
//! shares of the peaks, and the arithmetic intensity (flop per byte) that says which limit
//! applies.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::gpu::{Buffer, BufferDesc, ComputePipeline, Descriptor, Device, MemoryLocation, vk};
use crate::graph::{PassCost, PassTiming};
use crate::profile::report::ProfileReport;
use crate::shaders;

/// Invocations of the FMA kernel: enough to fill the largest GPU (an H100 holds about 270 000
/// resident threads).
pub const FMA_THREADS: u32 = 1 << 20;
/// Floating-point operations per loop iteration of the FMA kernel per invocation (32 vec4
/// FMAs).
pub const FMA_FLOPS_PER_ITERATION: u64 = 256;
/// Most loop iterations per invocation: llvmpipe ends an invocation's loops after 65 535.
pub const FMA_MAX_ITERATIONS: u32 = 65_535;
/// vec4 elements of each buffer of the copy kernel: 64 MiB, far beyond any cache.
pub const COPY_ELEMENTS: u32 = 1 << 22;
/// Most copies in one submission.
pub const COPY_MAX_REPEATS: u32 = 4096;
/// Shortest submission that counts, seconds: long enough that submission overhead and clock
/// resolution are below 0.1%.
pub const MIN_RUN_S: f64 = 0.05;
/// Timed runs of each kernel once calibrated; the fastest counts.
pub const RUNS: usize = 3;
/// Version of the kernels and their accounting: a cache entry of another version is measured
/// again.
pub const KERNEL_VERSION: u32 = 1;
/// The cache file in [`cache_dir`].
pub const CACHE_FILE: &str = "roofline.json";

/// Why the peaks could not be measured or cached.
#[derive(Debug, thiserror::Error)]
pub enum RooflineError {
    /// A Vulkan call of the micro-kernels failed.
    #[error("roofline micro-kernel: {0}")]
    Gpu(#[from] crate::gpu::Error),
    /// The cache could not be written (reading a damaged one only measures again).
    #[error("cannot write the roofline cache {path}: {source}")]
    Cache {
        /// The cache file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
}

/// A device's measured limits.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Peaks {
    /// Device name.
    pub device: String,
    /// Driver name and version.
    pub driver: String,
    /// [`KERNEL_VERSION`] of the measurement.
    pub version: u32,
    /// fp32 multiply-add peak, GFLOP/s.
    pub gflops: f64,
    /// Memory bandwidth (bytes read plus written), GB/s.
    pub gbps: f64,
}

/// Push constants of `shaders/roofline_fma.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct FmaPush {
    /// Steps per invocation.
    pub iterations: u32,
    /// Multiplier of every step.
    pub a: f32,
    /// Addend of every step.
    pub b: f32,
    /// Padding.
    pub pad: u32,
}

/// Push constants of `shaders/roofline_copy.comp`.
#[repr(C)]
#[derive(Debug, Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
pub struct CopyPush {
    /// vec4 elements copied.
    pub count: u32,
}

/// Seconds of the fastest of [`RUNS`] submissions of `record` (after one untimed run).
fn fastest(
    device: &Device,
    record: &dyn Fn(&mut crate::gpu::Commands) -> Result<(), crate::gpu::Error>,
) -> Result<f64, RooflineError> {
    let mut best = f64::INFINITY;
    for run in 0..=RUNS {
        let start = Instant::now();
        device.run_once(|cmd| record(cmd))?;
        if run > 0 {
            best = best.min(start.elapsed().as_secs_f64());
        }
    }
    Ok(best)
}

/// A storage buffer of `bytes` on the device.
fn storage(device: &Device, name: &'static str, bytes: u64) -> Result<Buffer, RooflineError> {
    Ok(Buffer::new(
        device,
        &BufferDesc {
            name,
            size: bytes,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
        },
    )?)
}

/// The fp32 FMA peak, GFLOP/s: iterations doubled until a run lasts [`MIN_RUN_S`].
fn measure_fma(device: &Device) -> Result<f64, RooflineError> {
    let pipeline = ComputePipeline::new(device, &shaders::ROOFLINE_FMA_COMP)?;
    let sink = storage(device, "roofline_sink", u64::from(FMA_THREADS) * 4)?;
    let mut iterations = 8u32;
    loop {
        let push = FmaPush {
            iterations,
            a: 0.999,
            b: 1e-3,
            pad: 0,
        };
        let seconds = fastest(device, &|cmd| {
            cmd.bind_compute(&pipeline, &[("sink", Descriptor::from(&sink))])?;
            cmd.push_constants(pipeline.layout(), bytemuck::bytes_of(&push))?;
            cmd.dispatch_threads(&pipeline, [FMA_THREADS, 1, 1]);
            Ok(())
        })?;
        if seconds >= MIN_RUN_S || iterations >= FMA_MAX_ITERATIONS {
            let flops = u64::from(FMA_THREADS) * u64::from(iterations) * FMA_FLOPS_PER_ITERATION;
            return Ok(flops as f64 / seconds / 1e9);
        }
        iterations = (iterations * 2).min(FMA_MAX_ITERATIONS);
    }
}

/// The memory bandwidth, GB/s: copies per submission doubled until a run lasts [`MIN_RUN_S`].
fn measure_bandwidth(device: &Device) -> Result<f64, RooflineError> {
    let pipeline = ComputePipeline::new(device, &shaders::ROOFLINE_COPY_COMP)?;
    let bytes = u64::from(COPY_ELEMENTS) * 16;
    let source = storage(device, "roofline_source", bytes)?;
    let target = storage(device, "roofline_target", bytes)?;
    let push = CopyPush {
        count: COPY_ELEMENTS,
    };
    let mut repeats = 1u32;
    loop {
        let seconds = fastest(device, &|cmd| {
            cmd.bind_compute(
                &pipeline,
                &[
                    ("source", Descriptor::from(&source)),
                    ("target", Descriptor::from(&target)),
                ],
            )?;
            cmd.push_constants(pipeline.layout(), bytemuck::bytes_of(&push))?;
            for _ in 0..repeats {
                cmd.dispatch_threads(&pipeline, [COPY_ELEMENTS, 1, 1]);
            }
            Ok(())
        })?;
        if seconds >= MIN_RUN_S || repeats >= COPY_MAX_REPEATS {
            return Ok((2 * bytes * u64::from(repeats)) as f64 / seconds / 1e9);
        }
        repeats *= 2;
    }
}

/// Measures `device`'s peaks (a second or two on lavapipe).
pub fn measure(device: &Device) -> Result<Peaks, RooflineError> {
    let info = device.info();
    Ok(Peaks {
        device: info.name.clone(),
        driver: info.driver.clone(),
        version: KERNEL_VERSION,
        gflops: measure_fma(device)?,
        gbps: measure_bandwidth(device)?,
    })
}

/// Where the peaks are cached: `$SHINE_CACHE_DIR`, else `$XDG_CACHE_HOME/shine`, else
/// `$HOME/.cache/shine`; `None` when none of them is set.
pub fn cache_dir() -> Option<PathBuf> {
    let var = |name| {
        std::env::var_os(name)
            .filter(|v| !v.is_empty())
            .map(PathBuf::from)
    };
    var("SHINE_CACHE_DIR")
        .or_else(|| var("XDG_CACHE_HOME").map(|d| d.join("shine")))
        .or_else(|| var("HOME").map(|d| d.join(".cache").join("shine")))
}

/// What [`cached`] found.
#[derive(Debug)]
pub struct Lookup {
    /// The device's peaks.
    pub peaks: Peaks,
    /// Whether they were measured now (not in the cache).
    pub measured: bool,
    /// Why peaks measured now could not be cached (they are still good for this run).
    pub not_cached: Option<RooflineError>,
}

/// The cached peaks of `device` in `dir`, or measured and added to the cache there. A missing
/// or unreadable cache, or an entry with a peak that is not positive, is measured again; a
/// cache that cannot be written leaves the measured peaks usable ([`Lookup::not_cached`]).
/// Errors only when the micro-kernels fail.
pub fn cached(device: &Device, dir: Option<&Path>) -> Result<Lookup, RooflineError> {
    let info = device.info();
    let path = dir.map(|d| d.join(CACHE_FILE));
    let mut entries: Vec<Peaks> = path
        .as_ref()
        .and_then(|p| std::fs::read(p).ok())
        .and_then(|bytes| serde_json::from_slice(&bytes).ok())
        .unwrap_or_default();
    let same =
        |p: &Peaks| p.device == info.name && p.driver == info.driver && p.version == KERNEL_VERSION;
    let usable = |p: &Peaks| p.gflops > 0.0 && p.gbps > 0.0;
    if let Some(found) = entries.iter().find(|p| same(p) && usable(p)) {
        return Ok(Lookup {
            peaks: found.clone(),
            measured: false,
            not_cached: None,
        });
    }
    let peaks = measure(device)?;
    let not_cached = match (dir, path) {
        (Some(dir), Some(path)) => {
            entries.retain(|p| !same(p));
            entries.push(peaks.clone());
            store(dir, &path, &entries).err()
        }
        _ => None,
    };
    Ok(Lookup {
        peaks,
        measured: true,
        not_cached,
    })
}

/// Writes `entries` to `path` in `dir` whole: to a temporary file, then renamed, so a reader
/// never sees half a file (the temporary file is removed if that fails).
fn store(dir: &Path, path: &Path, entries: &[Peaks]) -> Result<(), RooflineError> {
    let cache_error = |source| RooflineError::Cache {
        path: path.to_owned(),
        source,
    };
    std::fs::create_dir_all(dir).map_err(cache_error)?;
    let json = serde_json::to_vec_pretty(entries).map_err(|e| cache_error(e.into()))?;
    let partial = dir.join(format!("{CACHE_FILE}.{}.partial", std::process::id()));
    let written = std::fs::write(&partial, json).and_then(|()| std::fs::rename(&partial, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&partial);
    }
    written.map_err(cache_error)
}

/// One pass against the peaks: the declared work of every measured run of it over their summed
/// time (a pass whose work changes between frames, an amortised gather's full and sliced
/// frames, is weighed by what each run did).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassRoofline {
    /// The pass name.
    pub name: String,
    /// Its declared work, summed over the measured runs.
    pub flops: u64,
    /// Its declared memory traffic, summed over the measured runs, bytes.
    pub bytes: u64,
    /// Flops over time, GFLOP/s.
    pub gflops: f64,
    /// Bytes over time, GB/s.
    pub gbps: f64,
    /// `gflops` over the FMA peak, in [0, 1] for a correct count.
    pub flop_share: f64,
    /// `gbps` over the bandwidth, in [0, 1] for a correct count.
    pub byte_share: f64,
    /// Flop per byte: above the ridge point (peak GFLOP/s over GB/s) the pass is bound by
    /// arithmetic, below it by memory.
    pub intensity: f64,
}

/// The roofline part of a profile: the peaks and every pass that declared its work.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct RooflineReport {
    /// The device's limits.
    pub peaks: Peaks,
    /// Flop per byte where the two limits meet.
    pub ridge: f64,
    /// Passes with a declared [`PassCost`], in the report's order.
    pub passes: Vec<PassRoofline>,
}

impl RooflineReport {
    /// The passes of `report` (in its order) whose `timings` carry a cost, against `peaks`.
    pub fn new(report: &ProfileReport, timings: &[PassTiming], peaks: &Peaks) -> Self {
        let passes = report
            .passes
            .iter()
            .filter_map(|p| {
                // Every run of the pass must have declared its work.
                let (mut cost, mut seconds) = (PassCost::default(), 0.0);
                for t in timings.iter().filter(|t| t.name == p.name) {
                    let run = t.cost?;
                    cost.flops += run.flops;
                    cost.bytes += run.bytes;
                    seconds += (t.end_ns - t.begin_ns) / 1e9;
                }
                if cost.flops + cost.bytes == 0 {
                    return None;
                }
                let seconds = seconds.max(1e-12);
                let gflops = cost.flops as f64 / seconds / 1e9;
                let gbps = cost.bytes as f64 / seconds / 1e9;
                Some(PassRoofline {
                    name: p.name.clone(),
                    flops: cost.flops,
                    bytes: cost.bytes,
                    gflops,
                    gbps,
                    flop_share: gflops / peaks.gflops,
                    byte_share: gbps / peaks.gbps,
                    intensity: cost.flops as f64 / (cost.bytes as f64).max(1.0),
                })
            })
            .collect();
        Self {
            peaks: peaks.clone(),
            ridge: peaks.gflops / peaks.gbps,
            passes,
        }
    }

    /// Aligned columns: pass, GFLOP/s, share of the FMA peak, GB/s, share of the bandwidth,
    /// flop per byte.
    pub fn to_table(&self) -> String {
        use std::fmt::Write as _;
        let width = self
            .passes
            .iter()
            .map(|p| p.name.chars().count())
            .chain([4])
            .max()
            .unwrap_or(4);
        let mut out = format!(
            "Roofline of {} ({:.1} GFLOP/s fp32 FMA, {:.1} GB/s, ridge {:.2} flop/byte)\n\
             {:<width$}  {:>10}  {:>7}  {:>10}  {:>7}  {:>10}\n",
            self.peaks.device,
            self.peaks.gflops,
            self.peaks.gbps,
            self.ridge,
            "pass",
            "GFLOP/s",
            "peak",
            "GB/s",
            "peak",
            "flop/byte"
        );
        for p in &self.passes {
            // Writing into a String cannot fail.
            let _ = writeln!(
                out,
                "{:<width$}  {:>10.2}  {:>6.1}%  {:>10.3}  {:>6.1}%  {:>10.1}",
                p.name,
                p.gflops,
                100.0 * p.flop_share,
                p.gbps,
                100.0 * p.byte_share,
                p.intensity
            );
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::profile::report::PassClock;

    /// Achieved rates are the declared work of the runs over their summed time; passes without
    /// a declared cost are left out; the ridge is the peaks' ratio.
    #[test]
    fn shares_are_the_declared_work_over_the_time_it_took() {
        let cost = PassCost {
            flops: 2_000_000_000,
            bytes: 4_000_000,
        };
        let timing = |name: &str, frame: u64, ms: f64, cost: Option<PassCost>| PassTiming {
            name: name.to_owned(),
            begin_ns: 0.0,
            end_ns: ms * 1e6,
            frame,
            cost,
        };
        let timings: Vec<PassTiming> = (0..3)
            .flat_map(|f| {
                [
                    timing("gather", f, [4.0, 5.0, 11.0][f as usize], Some(cost)),
                    timing("blit", f, 1.0, None),
                ]
            })
            .collect();
        let report = ProfileReport::from_timings(&timings, PassClock::Host).unwrap();
        let peaks = Peaks {
            device: "test".into(),
            driver: "test".into(),
            version: KERNEL_VERSION,
            gflops: 1000.0,
            gbps: 10.0,
        };
        let roofline = RooflineReport::new(&report, &timings, &peaks);
        assert_eq!(roofline.passes.len(), 1);
        let gather = &roofline.passes[0];
        // 6 GFLOP and 12 MB in 20 ms: 300 GFLOP/s, 0.6 GB/s.
        assert_eq!((gather.flops, gather.bytes), (6_000_000_000, 12_000_000));
        assert!((gather.gflops - 300.0).abs() < 1e-9);
        assert!((gather.flop_share - 0.3).abs() < 1e-12);
        assert!((gather.gbps - 0.6).abs() < 1e-12);
        assert!((gather.byte_share - 0.06).abs() < 1e-12);
        assert!((gather.intensity - 500.0).abs() < 1e-12);
        assert!((roofline.ridge - 100.0).abs() < 1e-12);
        assert!(roofline.to_table().contains("gather"));
    }
}
