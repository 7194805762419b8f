//! `shine profile` reports: per-pass time statistics and a Chrome trace.
//!
//! Input is the [`PassTiming`]s of the measured frames (the caller drops the warm-up frames),
//! from GPU timestamps or from the host clock around passes submitted one by one
//! ([`PassClock`]).
//! Per pass: median, 95th percentile and mean of its GPU time per frame, in milliseconds, and
//! its share of the frame. Definitions:
//!
//! - A pass's time in a frame is the sum of its scopes with that name in that frame (a pass
//!   recorded twice counts once, summed); statistics run over the frames in which it ran.
//! - The frame time is the sum of every pass time of the frame: the GPU time spent inside
//!   passes. (The span from the first begin to the last end also counts the gaps between
//!   passes; it is reported as `span`.)
//! - Share = the pass's total time over all measured frames / the frames' total time, so the
//!   shares of all passes add up to 1.
//! - Median: the middle sample, or the mean of the two middle ones. p95: nearest rank, the
//!   ⌈0.95·n⌉-th smallest sample.

use std::fmt::Write as _;
use std::path::Path;
use std::str::FromStr;

use serde::Serialize;

use crate::capture::image_io::{self, ImageIoError};
use crate::graph::PassTiming;

/// Why a report could not be made or written.
#[derive(Debug, thiserror::Error)]
pub enum ProfileError {
    /// No pass timing at all: nothing ran, or every frame was dropped as warm-up.
    #[error("no GPU timings to report: render at least one frame after the warm-up frames")]
    NoTimings,
    /// A timing is not a finite, non-negative interval.
    #[error(
        "pass `{name}` of frame {frame} has an invalid GPU time ({begin_ns} ns to {end_ns} ns)"
    )]
    BadTiming {
        /// The pass.
        name: String,
        /// Its frame.
        frame: u64,
        /// Start, ns.
        begin_ns: f64,
        /// End, ns.
        end_ns: f64,
    },
    /// An unknown `--format` name.
    #[error("unknown report format `{0}`: expected table, json or csv")]
    UnknownFormat(String),
    /// Serializing the report or trace as JSON failed.
    #[error("cannot serialize the profile as JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// Writing the report or trace failed.
    #[error(transparent)]
    Write(#[from] ImageIoError),
}

/// The output formats of a profile report.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ReportFormat {
    /// Aligned columns for a terminal.
    Table,
    /// One JSON object (see [`ProfileReport`]'s fields).
    Json,
    /// One header line, then one line per pass and a `frame` line.
    Csv,
}

impl FromStr for ReportFormat {
    type Err = ProfileError;

    fn from_str(s: &str) -> Result<Self, ProfileError> {
        match s {
            "table" => Ok(Self::Table),
            "json" => Ok(Self::Json),
            "csv" => Ok(Self::Csv),
            _ => Err(ProfileError::UnknownFormat(s.to_owned())),
        }
    }
}

/// Summary statistics of per-frame times, in milliseconds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Stats {
    /// Number of samples (frames).
    pub samples: usize,
    /// Median.
    pub median_ms: f64,
    /// 95th percentile (nearest rank).
    pub p95_ms: f64,
    /// Arithmetic mean.
    pub mean_ms: f64,
    /// Smallest sample.
    pub min_ms: f64,
    /// Largest sample.
    pub max_ms: f64,
}

impl Stats {
    /// Statistics of `samples_ns` (nanoseconds); `None` when empty.
    pub fn from_ns(samples_ns: &[f64]) -> Option<Self> {
        let mut ms: Vec<f64> = samples_ns.iter().map(|ns| ns / 1e6).collect();
        ms.sort_by(f64::total_cmp);
        let n = ms.len();
        let (&min_ms, &max_ms) = (ms.first()?, ms.last()?);
        let median_ms = if n % 2 == 1 {
            ms[n / 2]
        } else {
            0.5 * (ms[n / 2 - 1] + ms[n / 2])
        };
        let rank = (0.95 * n as f64).ceil() as usize;
        Some(Self {
            samples: n,
            median_ms,
            p95_ms: ms[rank.clamp(1, n) - 1],
            mean_ms: ms.iter().sum::<f64>() / n as f64,
            min_ms,
            max_ms,
        })
    }
}

/// One pass's line of the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct PassStats {
    /// The pass name.
    pub name: String,
    /// Its GPU time per frame.
    pub time: Stats,
    /// Its share of the measured frames' total GPU time, in [0, 1].
    pub share: f64,
}

/// Which clock timed the passes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PassClock {
    /// GPU timestamps around each pass of a whole-frame submission.
    Gpu,
    /// Host time from submit to completion of each pass submitted alone
    /// ([`crate::graph::Executor::execute_serialized`]): for devices whose timestamps do not
    /// bracket compute work (lavapipe).
    Host,
}

impl PassClock {
    /// The clock `shine profile` uses by default on a device of `device_type`: host timing on
    /// CPU implementations (lavapipe writes timestamps when it flushes rasterisation, so a
    /// compute pass's time lands outside its own scope), GPU timestamps elsewhere.
    pub fn for_device(device_type: crate::gpu::vk::PhysicalDeviceType) -> Self {
        if device_type == crate::gpu::vk::PhysicalDeviceType::CPU {
            Self::Host
        } else {
            Self::Gpu
        }
    }

    /// `gpu` or `host`.
    pub fn name(self) -> &'static str {
        match self {
            Self::Gpu => "gpu",
            Self::Host => "host",
        }
    }
}

/// Per-pass time statistics over the measured frames.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProfileReport {
    /// The clock that timed the passes.
    pub clock: PassClock,
    /// Number of frames measured.
    pub frames: usize,
    /// Passes in order of first execution.
    pub passes: Vec<PassStats>,
    /// The frame time (sum of its pass times).
    pub frame: Stats,
    /// The frame span: first pass begin to last pass end.
    pub span: Stats,
}

/// Per frame (in order of appearance): the pass times by name (in order of first appearance)
/// and the span.
struct FrameTimes {
    frame: u64,
    passes: Vec<(String, f64)>,
    begin: f64,
    end: f64,
}

/// Groups timings by frame, checking each interval.
fn frames(timings: &[PassTiming]) -> Result<Vec<FrameTimes>, ProfileError> {
    let mut frames: Vec<FrameTimes> = Vec::new();
    for t in timings {
        let duration = t.end_ns - t.begin_ns;
        if !(t.begin_ns.is_finite() && t.end_ns.is_finite() && duration >= 0.0) {
            return Err(ProfileError::BadTiming {
                name: t.name.clone(),
                frame: t.frame,
                begin_ns: t.begin_ns,
                end_ns: t.end_ns,
            });
        }
        let index = match frames.iter().position(|f| f.frame == t.frame) {
            Some(index) => index,
            None => {
                frames.push(FrameTimes {
                    frame: t.frame,
                    passes: Vec::new(),
                    begin: t.begin_ns,
                    end: t.end_ns,
                });
                frames.len() - 1
            }
        };
        let frame = &mut frames[index];
        frame.begin = frame.begin.min(t.begin_ns);
        frame.end = frame.end.max(t.end_ns);
        match frame.passes.iter_mut().find(|(name, _)| *name == t.name) {
            Some((_, time)) => *time += duration,
            None => frame.passes.push((t.name.clone(), duration)),
        }
    }
    Ok(frames)
}

impl ProfileReport {
    /// Computes the report from the timings of the measured frames, taken with `clock`.
    pub fn from_timings(timings: &[PassTiming], clock: PassClock) -> Result<Self, ProfileError> {
        let frames = frames(timings)?;
        let mut names: Vec<&str> = Vec::new();
        for frame in &frames {
            for (name, _) in &frame.passes {
                if !names.contains(&name.as_str()) {
                    names.push(name);
                }
            }
        }
        let totals: Vec<f64> = frames
            .iter()
            .map(|f| f.passes.iter().map(|(_, t)| t).sum())
            .collect();
        let spans: Vec<f64> = frames.iter().map(|f| f.end - f.begin).collect();
        let grand_total: f64 = totals.iter().sum();
        let passes = names
            .iter()
            .map(|&name| {
                let samples: Vec<f64> = frames
                    .iter()
                    .filter_map(|f| f.passes.iter().find(|(n, _)| n == name).map(|(_, t)| *t))
                    .collect();
                let total: f64 = samples.iter().sum();
                Ok::<_, ProfileError>(PassStats {
                    name: name.to_owned(),
                    time: Stats::from_ns(&samples).ok_or(ProfileError::NoTimings)?,
                    share: if grand_total > 0.0 {
                        total / grand_total
                    } else {
                        0.0
                    },
                })
            })
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Self {
            clock,
            frames: frames.len(),
            passes,
            frame: Stats::from_ns(&totals).ok_or(ProfileError::NoTimings)?,
            span: Stats::from_ns(&spans).ok_or(ProfileError::NoTimings)?,
        })
    }

    /// The report in `format`.
    pub fn format(&self, format: ReportFormat) -> Result<String, ProfileError> {
        match format {
            ReportFormat::Table => Ok(self.to_table()),
            ReportFormat::Json => self.to_json(),
            ReportFormat::Csv => Ok(self.to_csv()),
        }
    }

    /// Aligned columns: pass, median, p95, mean (ms), share (%), then the frame lines.
    pub fn to_table(&self) -> String {
        let width = self
            .passes
            .iter()
            .map(|p| p.name.chars().count())
            .chain([5])
            .max()
            .unwrap_or(5);
        let heading = match self.clock {
            PassClock::Gpu => "GPU time (timestamps)",
            PassClock::Host => "Time per pass submitted alone (host clock)",
        };
        let mut out = format!(
            "{heading} over {} frame(s), ms\n{:<width$}  {:>10}  {:>10}  {:>10}  {:>7}\n",
            self.frames, "pass", "median", "p95", "mean", "share"
        );
        let mut line = |name: &str, s: &Stats, share: f64| {
            // Writing into a String cannot fail.
            let _ = writeln!(
                out,
                "{name:<width$}  {:>10.4}  {:>10.4}  {:>10.4}  {:>6.1}%",
                s.median_ms,
                s.p95_ms,
                s.mean_ms,
                share * 100.0
            );
        };
        for p in &self.passes {
            line(&p.name, &p.time, p.share);
        }
        line("frame", &self.frame, 1.0);
        let _ = writeln!(
            out,
            "{:<width$}  {:>10.4}  {:>10.4}  {:>10.4}",
            "span", self.span.median_ms, self.span.p95_ms, self.span.mean_ms
        );
        out
    }

    /// The report as pretty-printed JSON (this struct's fields).
    pub fn to_json(&self) -> Result<String, ProfileError> {
        Ok(serde_json::to_string_pretty(self)?)
    }

    /// CSV: `pass,samples,median_ms,p95_ms,mean_ms,share`, one line per pass, then `frame`
    /// and `span`. Pass names are quoted when they hold a comma or a quote.
    pub fn to_csv(&self) -> String {
        let mut out = String::from("pass,samples,median_ms,p95_ms,mean_ms,share\n");
        let mut line = |name: &str, s: &Stats, share: f64| {
            let _ = writeln!(
                out,
                "{},{},{},{},{},{}",
                csv_field(name),
                s.samples,
                s.median_ms,
                s.p95_ms,
                s.mean_ms,
                share
            );
        };
        for p in &self.passes {
            line(&p.name, &p.time, p.share);
        }
        line("frame", &self.frame, 1.0);
        line("span", &self.span, 1.0);
        out
    }
}

/// A CSV field, quoted (RFC 4180) when needed.
fn csv_field(text: &str) -> String {
    if text.contains([',', '"', '\n']) {
        format!("\"{}\"", text.replace('"', "\"\""))
    } else {
        text.to_owned()
    }
}

/// One event of a Chrome trace (the Trace Event Format Perfetto and chrome://tracing read).
#[derive(Serialize)]
struct TraceEvent {
    name: String,
    cat: &'static str,
    ph: &'static str,
    /// Microseconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    ts: Option<f64>,
    /// Microseconds.
    #[serde(skip_serializing_if = "Option::is_none")]
    dur: Option<f64>,
    pid: u32,
    tid: u32,
    args: serde_json::Value,
}

/// The whole trace document.
#[derive(Serialize)]
#[serde(rename_all = "camelCase")]
struct Trace {
    trace_events: Vec<TraceEvent>,
    display_time_unit: &'static str,
}

/// The timings as Chrome trace JSON: one track ("GPU"), one complete (`ph: "X"`) event per
/// pass inside one `frame N` event per frame, `ts`/`dur` in microseconds.
///
/// GPU timestamps are relative to each frame's first pass, so frames are laid end to end in
/// the order given (the idle time between frames is not measured).
pub fn chrome_trace(timings: &[PassTiming]) -> Result<String, ProfileError> {
    let frames = frames(timings)?;
    let (pid, tid) = (1, 1);
    let metadata = |name: &'static str, value: &str| TraceEvent {
        name: name.to_owned(),
        cat: "__metadata",
        ph: "M",
        ts: None,
        dur: None,
        pid,
        tid,
        args: serde_json::json!({ "name": value }),
    };
    let mut events = vec![
        metadata("process_name", "shine"),
        metadata("thread_name", "GPU"),
    ];
    let mut offset_ns = 0.0;
    for frame in &frames {
        events.push(TraceEvent {
            name: format!("frame {}", frame.frame),
            cat: "frame",
            ph: "X",
            ts: Some(offset_ns / 1e3),
            dur: Some((frame.end - frame.begin) / 1e3),
            pid,
            tid,
            args: serde_json::json!({ "frame": frame.frame }),
        });
        for t in timings.iter().filter(|t| t.frame == frame.frame) {
            events.push(TraceEvent {
                name: t.name.clone(),
                cat: "pass",
                ph: "X",
                ts: Some((offset_ns + t.begin_ns - frame.begin) / 1e3),
                dur: Some((t.end_ns - t.begin_ns) / 1e3),
                pid,
                tid,
                args: serde_json::json!({ "frame": t.frame }),
            });
        }
        offset_ns += frame.end - frame.begin;
    }
    let trace = Trace {
        trace_events: events,
        display_time_unit: "ms",
    };
    Ok(serde_json::to_string(&trace)?)
}

/// Writes the Chrome trace of `timings` to `path`, atomically.
pub fn write_chrome_trace(path: &Path, timings: &[PassTiming]) -> Result<(), ProfileError> {
    let json = chrome_trace(timings)?;
    image_io::write_bytes_atomically(path, json.as_bytes())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn timing(name: &str, frame: u64, begin_ms: f64, end_ms: f64) -> PassTiming {
        PassTiming {
            name: name.to_owned(),
            begin_ns: begin_ms * 1e6,
            end_ns: end_ms * 1e6,
            frame,
            cost: None,
        }
    }

    /// Five frames: `a` takes 1, 2, 3, 4, 10 ms; then a 0.5 ms gap; then `b` takes 1 ms.
    fn five_frames() -> Vec<PassTiming> {
        let mut timings = Vec::new();
        for (frame, a) in [1.0, 2.0, 3.0, 4.0, 10.0].into_iter().enumerate() {
            timings.push(timing("a", frame as u64 + 7, 0.0, a));
            timings.push(timing("b", frame as u64 + 7, a + 0.5, a + 1.5));
        }
        timings
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn statistics_by_hand() {
        let report = ProfileReport::from_timings(&five_frames(), PassClock::Gpu).unwrap();
        assert_eq!(report.frames, 5);
        let a = &report.passes[0];
        assert_eq!(a.name, "a");
        assert_eq!(a.time.samples, 5);
        // Sorted 1, 2, 3, 4, 10: median 3, mean 20/5, p95 = 5th smallest (⌈4.75⌉).
        assert!(close(a.time.median_ms, 3.0));
        assert!(close(a.time.mean_ms, 4.0));
        assert!(close(a.time.p95_ms, 10.0));
        assert!(close(a.time.min_ms, 1.0) && close(a.time.max_ms, 10.0));
        // Totals: a 20 ms, b 5 ms.
        assert!(close(a.share, 0.8));
        let b = &report.passes[1];
        assert!(close(b.time.median_ms, 1.0) && close(b.time.p95_ms, 1.0));
        assert!(close(b.share, 0.2));
        // Frame = a + b: 2, 3, 4, 5, 11.
        assert!(close(report.frame.median_ms, 4.0));
        assert!(close(report.frame.mean_ms, 5.0));
        assert!(close(report.frame.p95_ms, 11.0));
        // Span adds the 0.5 ms gap: 2.5 … 11.5.
        assert!(close(report.span.median_ms, 4.5));
        assert!(close(report.span.mean_ms, 5.5));
    }

    #[test]
    fn even_counts_and_p95_rank() {
        let s = Stats::from_ns(&[4e6, 1e6, 3e6, 2e6]).unwrap();
        assert!(close(s.median_ms, 2.5));
        assert!(close(s.p95_ms, 4.0));
        // 20 samples 1..=20 ms: p95 is the 19th smallest.
        let twenty: Vec<f64> = (1..=20).map(|i| f64::from(i) * 1e6).collect();
        let s = Stats::from_ns(&twenty).unwrap();
        assert!(close(s.p95_ms, 19.0));
        assert!(close(s.median_ms, 10.5));
        assert!(close(s.mean_ms, 10.5));
        let one = Stats::from_ns(&[7e6]).unwrap();
        assert!(close(one.median_ms, 7.0) && close(one.p95_ms, 7.0));
        assert_eq!(Stats::from_ns(&[]), None);
    }

    #[test]
    fn repeated_and_intermittent_passes() {
        let timings = [
            timing("a", 0, 0.0, 1.0),
            timing("a", 0, 2.0, 4.0),
            timing("gi", 0, 4.0, 8.0),
            timing("a", 1, 0.0, 3.0),
        ];
        let report = ProfileReport::from_timings(&timings, PassClock::Gpu).unwrap();
        let a = &report.passes[0];
        // Frame 0: 1 + 2 ms; frame 1: 3 ms.
        assert_eq!(a.time.samples, 2);
        assert!(close(a.time.mean_ms, 3.0));
        let gi = &report.passes[1];
        assert_eq!(gi.time.samples, 1);
        // 6 ms of a, 4 ms of gi.
        assert!(close(gi.share, 0.4));
    }

    #[test]
    fn bad_input_is_an_error() {
        assert!(matches!(
            ProfileReport::from_timings(&[], PassClock::Gpu),
            Err(ProfileError::NoTimings)
        ));
        let message = ProfileReport::from_timings(&[timing("x", 3, 2.0, 1.0)], PassClock::Gpu)
            .unwrap_err()
            .to_string();
        assert!(message.contains("`x` of frame 3"), "{message}");
        let message = "xml".parse::<ReportFormat>().unwrap_err().to_string();
        assert!(message.contains("table, json or csv"), "{message}");
    }

    #[test]
    fn formats() {
        let timings = [timing("a", 0, 0.0, 3.0), timing("b, c", 0, 3.0, 4.0)];
        let report = ProfileReport::from_timings(&timings, PassClock::Gpu).unwrap();
        assert_eq!(
            report.to_csv(),
            "pass,samples,median_ms,p95_ms,mean_ms,share\n\
             a,1,3,3,3,0.75\n\
             \"b, c\",1,1,1,1,0.25\n\
             frame,1,4,4,4,1\n\
             span,1,4,4,4,1\n"
        );
        let table = report.format("table".parse().unwrap()).unwrap();
        assert!(table.contains("median"), "{table}");
        assert!(table.contains("75.0%"), "{table}");
        assert!(table.contains("frame"), "{table}");
        let json: serde_json::Value =
            serde_json::from_str(&report.format(ReportFormat::Json).unwrap()).unwrap();
        assert_eq!(json["passes"][0]["name"], "a");
        assert_eq!(json["passes"][0]["share"], 0.75);
        assert_eq!(json["frame"]["median_ms"], 4.0);
    }

    #[test]
    fn chrome_trace_lays_frames_end_to_end() {
        let trace: serde_json::Value =
            serde_json::from_str(&chrome_trace(&five_frames()).unwrap()).unwrap();
        let events = trace["traceEvents"].as_array().unwrap();
        let complete: Vec<&serde_json::Value> = events.iter().filter(|e| e["ph"] == "X").collect();
        // 5 frame events + 10 pass events, all on one track.
        assert_eq!(complete.len(), 15);
        assert!(events.iter().all(|e| e["pid"] == 1 && e["tid"] == 1));
        let passes: Vec<(&str, f64, f64)> = complete
            .iter()
            .filter(|e| e["cat"] == "pass")
            .map(|e| {
                (
                    e["name"].as_str().unwrap(),
                    e["ts"].as_f64().unwrap(),
                    e["dur"].as_f64().unwrap(),
                )
            })
            .collect();
        // Frame 0 spans 2.5 ms = 2500 µs: frame 1's `a` starts there.
        assert_eq!(passes[0], ("a", 0.0, 1000.0));
        assert_eq!(passes[1], ("b", 1500.0, 1000.0));
        assert_eq!(passes[2], ("a", 2500.0, 2000.0));
        let frames: Vec<f64> = complete
            .iter()
            .filter(|e| e["cat"] == "frame")
            .map(|e| e["dur"].as_f64().unwrap())
            .collect();
        assert_eq!(frames, [2500.0, 3500.0, 4500.0, 5500.0, 11500.0]);
        assert_eq!(complete[0]["name"], "frame 7");
        assert_eq!(complete[0]["args"]["frame"], 7);
    }

    #[test]
    fn trace_file_is_written() {
        let path = std::env::temp_dir().join(format!("shine-trace-{}.json", std::process::id()));
        write_chrome_trace(&path, &five_frames()).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        std::fs::remove_file(&path).unwrap();
        assert!(text.starts_with("{\"traceEvents\":["), "{text}");
    }
}
