//! Sharded work on a real Slurm (issue 46): the test brings up a single-node cluster from
//! Debian's slurm-wlm and munge (scripts/slurm/local-cluster.sh, four task slots), submits the
//! sbatch templates of scripts/slurm/ as 4-task job arrays with their dependent merge jobs,
//! checks what they wrote against one-process runs, kills and re-queues a task mid-sequence,
//! and shuts the cluster down. Where Slurm is missing it fails, saying so: it never skips.

mod common;

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, Instant};

use common::cli::{assert_same_files, scratch, text, worst_relative};
use shine::capture::image_io::read_exr;

/// Longest wait for a job array and its merge.
const JOB_TIMEOUT: Duration = Duration::from_secs(900);
/// The sequence: 16 frames of the animated scene, 4 tasks.
const SEQUENCE_FRAMES: u32 = 16;
/// The reference: 256 samples per pixel, 4 tasks.
const REFERENCE_SPP: u32 = 256;
/// Frames of the sequence whose task is killed: long enough that the task is still rendering
/// when its first frame appears.
const FAULT_FRAMES: u32 = 48;
/// Image side of every run.
const SIZE: &str = "32";
/// Largest per-pixel difference of the merged reference from the one-process one, relative to
/// the pixel (plus an absolute floor for black pixels): the parts hold the same samples, added
/// in another order (docs/many-machines.md).
const MERGE_TOLERANCE: f32 = 1e-5;

/// The repository's root.
fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// A running single-node cluster, shut down on drop.
struct Cluster {
    dir: PathBuf,
}

impl Cluster {
    /// Starts the cluster under `dir`, or fails the test with the reason.
    fn up(dir: &Path) -> Self {
        for tool in [
            "slurmctld",
            "slurmd",
            "munged",
            "sbatch",
            "scontrol",
            "squeue",
        ] {
            let found = Command::new("sh")
                .args(["-c", &format!("command -v {tool}")])
                .output()
                .is_ok_and(|o| o.status.success());
            assert!(
                found,
                "{tool} is not installed: this test needs Debian's slurm-wlm and munge \
                 (scripts/install-deps.sh and .ci/run install them)"
            );
        }
        let [ctld, slurmd] = free_ports();
        let out = Command::new(root().join("scripts/slurm/local-cluster.sh"))
            .args(["up", dir.to_str().unwrap(), "4"])
            .env("SLURMCTLD_PORT", ctld.to_string())
            .env("SLURMD_PORT", slurmd.to_string())
            .output()
            .expect("run local-cluster.sh");
        let cluster = Self {
            dir: dir.to_owned(),
        };
        assert!(
            out.status.success(),
            "the cluster did not come up:\n{}",
            text(&out)
        );
        cluster
    }

    /// A Slurm command against this cluster.
    fn command(&self, program: &str) -> Command {
        let mut c = Command::new(program);
        c.env("SLURM_CONF", self.dir.join("slurm.conf"));
        c
    }

    /// Runs a Slurm command, failing the test unless it succeeds.
    fn run(&self, program: &str, args: &[&str]) -> String {
        let out = self.command(program).args(args).output().expect(program);
        assert!(
            out.status.success(),
            "{program} {args:?} failed:\n{}",
            text(&out)
        );
        String::from_utf8_lossy(&out.stdout).trim().to_owned()
    }

    /// Submits `script` with `options` before it and `args` after it; the job's id.
    fn sbatch(&self, options: &[&str], script: &str, args: &[&str], logs: &Path) -> String {
        let output = format!("--output={}/%x-%A_%a.out", logs.display());
        let mut all = vec!["--parsable", output.as_str()];
        all.extend_from_slice(options);
        let script = root().join("scripts/slurm").join(script);
        all.push(script.to_str().unwrap());
        all.extend_from_slice(args);
        let out = self
            .command("sbatch")
            .args(&all)
            .env("SHINE", env!("CARGO_BIN_EXE_shine"))
            .env("SHINE_VALIDATION", "1")
            .output()
            .expect("sbatch");
        assert!(out.status.success(), "sbatch {all:?}:\n{}", text(&out));
        let id = String::from_utf8_lossy(&out.stdout).trim().to_owned();
        id.split(';').next().unwrap().to_owned()
    }

    /// Every job of `ids` with its array tasks: (job id, state, restarts).
    fn states(&self, ids: &[&str]) -> Vec<(String, String, u32)> {
        let mut states = Vec::new();
        for id in ids {
            let shown = self.run("scontrol", &["show", "job", "--oneliner", id]);
            for line in shown.lines() {
                let field = |key: &str| {
                    line.split_whitespace()
                        .find_map(|f| f.strip_prefix(key))
                        .unwrap_or("")
                        .to_owned()
                };
                let task = field("ArrayTaskId=");
                let job = if task.is_empty() {
                    field("JobId=")
                } else {
                    format!("{id}_{task}")
                };
                let restarts = field("Restarts=").parse().unwrap_or(0);
                states.push((job, field("JobState="), restarts));
            }
        }
        states
    }

    /// Waits until no job of `ids` is pending or running; fails the test after
    /// [`JOB_TIMEOUT`], showing the jobs and the logs.
    fn wait(&self, ids: &[&str], logs: &Path) {
        let start = Instant::now();
        loop {
            let states = self.states(ids);
            let active = |s: &str| {
                matches!(
                    s,
                    "PENDING" | "RUNNING" | "REQUEUED" | "COMPLETING" | "CONFIGURING"
                )
            };
            if !states.iter().any(|(_, s, _)| active(s)) {
                return;
            }
            assert!(
                start.elapsed() < JOB_TIMEOUT,
                "jobs still running after {JOB_TIMEOUT:?}: {states:?}\n{}",
                read_logs(logs)
            );
            std::thread::sleep(Duration::from_millis(200));
        }
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let _ = Command::new(root().join("scripts/slurm/local-cluster.sh"))
            .args(["down", self.dir.to_str().unwrap()])
            .output();
    }
}

/// Two TCP ports nothing listens on now.
fn free_ports() -> [u16; 2] {
    let a = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    let b = std::net::TcpListener::bind("127.0.0.1:0").unwrap();
    [
        a.local_addr().unwrap().port(),
        b.local_addr().unwrap().port(),
    ]
}

/// Every job log under `logs`, for failure messages.
fn read_logs(logs: &Path) -> String {
    let mut all = String::new();
    for entry in std::fs::read_dir(logs).into_iter().flatten().flatten() {
        let body = std::fs::read_to_string(entry.path()).unwrap_or_default();
        all.push_str(&format!("--- {}\n{body}\n", entry.path().display()));
    }
    all
}

/// Runs `shine` with `args` in one process, failing the test unless it succeeds.
fn shine(args: &[&str]) -> Output {
    let out = Command::new(env!("CARGO_BIN_EXE_shine"))
        .args(args)
        .env("SHINE_VALIDATION", "1")
        .output()
        .expect("run shine");
    assert!(out.status.success(), "shine {args:?}:\n{}", text(&out));
    assert!(!text(&out).contains("[vulkan"), "{}", text(&out));
    out
}

/// Asserts that every frame `0..frames` of `dir` equals the one in `one` bit for bit.
fn same_frames(dir: &Path, one: &Path, frames: u32) {
    let names: Vec<String> = (0..frames).map(|k| format!("frame_{k:04}.png")).collect();
    assert_same_files(dir, one, &names);
}

/// Asserts that `dir` holds no temporary file of an interrupted write.
fn no_temporaries(dir: &Path) {
    for entry in std::fs::read_dir(dir).unwrap().flatten() {
        let name = entry.file_name().to_string_lossy().into_owned();
        assert!(
            !name.ends_with(".tmp"),
            "{name} was left in {}",
            dir.display()
        );
    }
}

#[test]
fn job_arrays_on_a_real_slurm_equal_one_process_runs() {
    let dir = scratch("slurm");
    let logs = dir.join("logs");
    std::fs::create_dir_all(&logs).unwrap();
    // The cluster's socket paths must stay short (108 bytes): under /tmp, not the target dir.
    let cluster_dir = std::env::temp_dir().join(format!("shine-slurm-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&cluster_dir);
    let cluster = Cluster::up(&cluster_dir);
    let (seq, refs, fault) = (dir.join("seq"), dir.join("ref"), dir.join("fault"));
    let frames = SEQUENCE_FRAMES.to_string();
    let spp = REFERENCE_SPP.to_string();
    let size = ["--width", SIZE, "--height", SIZE];

    // 1. A 16-frame sequence and a 256-spp reference, each a 4-task array with a merge after it.
    let array = ["--array=0-3"];
    let mut sequence_args = vec!["builtin:animated", seq.to_str().unwrap(), &frames];
    sequence_args.extend_from_slice(&size);
    let seq_job = cluster.sbatch(&array, "sequence.sbatch", &sequence_args, &logs);
    let mut reference_args = vec!["builtin:cornell-box", refs.to_str().unwrap(), &spp];
    reference_args.extend_from_slice(&size);
    reference_args.push("--indirect-only");
    let ref_job = cluster.sbatch(&array, "reference.sbatch", &reference_args, &logs);
    let after = |job: &str| format!("--dependency=afterok:{job}");
    let (seq_after, ref_after) = (after(&seq_job), after(&ref_job));
    let seq_merge = cluster.sbatch(
        &[&seq_after],
        "merge.sbatch",
        &["sequence", seq.to_str().unwrap()],
        &logs,
    );
    let ref_merge = cluster.sbatch(
        &[&ref_after],
        "merge.sbatch",
        &["reference", refs.to_str().unwrap()],
        &logs,
    );

    // 2. The fault: a longer sequence whose task 1 is re-queued once its first frame is out,
    // while it renders the next ones.
    let fault_frames = FAULT_FRAMES.to_string();
    let mut fault_args = vec!["builtin:animated", fault.to_str().unwrap(), &fault_frames];
    fault_args.extend_from_slice(&size);
    let fault_job = cluster.sbatch(&array, "sequence.sbatch", &fault_args, &logs);
    let first_of_task_1 = fault.join(format!("frame_{:04}.png", FAULT_FRAMES / 4));
    let start = Instant::now();
    while !first_of_task_1.exists() {
        assert!(
            start.elapsed() < JOB_TIMEOUT,
            "task 1 wrote nothing:\n{}",
            read_logs(&logs)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    let task = format!("{fault_job}_1");
    let states = cluster.states(&[&task]);
    assert_eq!(
        states[0].1, "RUNNING",
        "task 1 finished before it could be killed: {states:?}"
    );
    // What a write killed half-way leaves: a temporary file beside the frame.
    let torn = fault.join(format!(".frame_{:04}.png.4242-0.tmp", FAULT_FRAMES / 4 + 1));
    std::fs::write(&torn, b"half a png").unwrap();
    cluster.run("scontrol", &["requeue", &task]);
    let fault_after = after(&fault_job);
    let fault_merge = cluster.sbatch(
        &[&fault_after],
        "merge.sbatch",
        &["sequence", fault.to_str().unwrap()],
        &logs,
    );

    // Meanwhile, the one-process runs.
    let one = dir.join("one");
    std::fs::create_dir_all(&one).unwrap();
    let mut render = vec![
        "render",
        "builtin:animated",
        "--frames",
        &fault_frames,
        "-o",
    ];
    let pattern = one.join("frame_%04d.png");
    render.push(pattern.to_str().unwrap());
    render.extend_from_slice(&size);
    shine(&render);
    let one_short = dir.join("one-short");
    std::fs::create_dir_all(&one_short).unwrap();
    let pattern = one_short.join("frame_%04d.png");
    let mut render_short = vec!["render", "builtin:animated", "--frames", &frames, "-o"];
    render_short.push(pattern.to_str().unwrap());
    render_short.extend_from_slice(&size);
    shine(&render_short);
    let one_ref = one.join("reference.exr");
    let mut reference = vec!["reference", "builtin:cornell-box", "--spp", &spp, "-o"];
    reference.push(one_ref.to_str().unwrap());
    reference.extend_from_slice(&size);
    reference.push("--indirect-only");
    shine(&reference);

    let jobs = [
        seq_job.as_str(),
        ref_job.as_str(),
        seq_merge.as_str(),
        ref_merge.as_str(),
        fault_job.as_str(),
        fault_merge.as_str(),
    ];
    cluster.wait(&jobs, &logs);
    let states = cluster.states(&jobs);
    let all_logs = read_logs(&logs);
    for (job, state, _) in &states {
        assert_eq!(state, "COMPLETED", "{job}: {states:?}\n{all_logs}");
    }
    assert!(
        !all_logs.contains("[vulkan"),
        "validation messages:\n{all_logs}"
    );

    // The sequence: every frame the one-process run's, bit for bit, and the merge's manifest
    // lists each once.
    same_frames(&seq, &one_short, SEQUENCE_FRAMES);
    let manifest = std::fs::read_to_string(seq.join("sequence.json")).unwrap();
    let manifest: serde_json::Value = serde_json::from_str(&manifest).unwrap();
    assert_eq!(
        manifest["files"].as_array().unwrap().len(),
        SEQUENCE_FRAMES as usize
    );

    // The reference: the one-process one up to the order of additions.
    let merged = read_exr(&refs.join("reference.exr")).unwrap();
    let single = read_exr(&one_ref).unwrap();
    let worst = worst_relative(&merged.texels, &single.texels);
    assert!(
        worst <= MERGE_TOLERANCE,
        "merged reference differs by {worst} (relative)"
    );

    // The fault: task 1 ran twice, and its frames came out whole and identical.
    let restarts = cluster.states(&[&task]);
    assert!(restarts[0].2 >= 1, "task 1 was not re-queued: {restarts:?}");
    same_frames(&fault, &one, FAULT_FRAMES);
    no_temporaries(&fault);
    drop(cluster);
    let _ = std::fs::remove_dir_all(&cluster_dir);
}
