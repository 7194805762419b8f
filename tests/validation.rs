//! The validation plumbing itself: a test device really runs the Khronos layer with
//! synchronization validation, and the messenger counts what it reports. Without this, "zero
//! messages" in every other GPU test could mean "nothing was listening".

mod common;

use shine::gpu::{ComputePipeline, Descriptor, vk};

#[test]
fn a_missing_barrier_is_reported_as_a_sync_hazard() {
    let device = common::device();
    assert!(
        device.info().validation,
        "the test device must run the validation layer"
    );
    let pipeline =
        ComputePipeline::new(&device, &shine::shaders::SH_EVAL_COMP_BANDS1).expect("pipeline");
    let usage = vk::BufferUsageFlags::STORAGE_BUFFER
        | vk::BufferUsageFlags::TRANSFER_SRC
        | vk::BufferUsageFlags::TRANSFER_DST;
    let buffer = |name| common::buffer(&device, name, 1024, usage);
    let (input, output, copy) = (buffer("in"), buffer("out"), buffer("copy"));
    let count = 16u32;
    device
        .run_once(|cmd| {
            cmd.bind_compute(
                &pipeline,
                &[
                    ("directions", Descriptor::from(&input)),
                    ("coefficients", Descriptor::from(&output)),
                ],
            )?;
            cmd.push_constants(pipeline.layout(), bytemuck::bytes_of(&count))?;
            cmd.dispatch_threads(&pipeline, [count, 1, 1]);
            // Deliberately no barrier between the shader write and the copy's read.
            cmd.copy_buffer(output.raw(), copy.raw(), &[COPY_256]);
            Ok(())
        })
        .expect("submission");
    device.wait_idle().expect("idle");
    let counts = device.message_counts();
    let messages = device.messages().join("\n");
    assert!(counts.problems() >= 1, "the hazard went unreported");
    assert!(
        messages.contains("SYNC-HAZARD-READ-AFTER-WRITE"),
        "expected a read-after-write hazard, got:\n{messages}"
    );
}

#[test]
fn bad_bindings_are_errors_not_panics() {
    let device = common::device();
    let pipeline =
        ComputePipeline::new(&device, &shine::shaders::SH_EVAL_COMP_BANDS1).expect("pipeline");
    let buffer = common::buffer(&device, "b", 64, vk::BufferUsageFlags::STORAGE_BUFFER);
    let mut cmd = device.begin_commands().expect("commands");
    let missing = cmd.bind_compute(&pipeline, &[("directions", Descriptor::from(&buffer))]);
    let message = missing
        .expect_err("a missing binding must fail")
        .to_string();
    assert!(message.contains("coefficients"), "{message}");
    let unknown = cmd.bind_compute(&pipeline, &[("nope", Descriptor::from(&buffer))]);
    assert!(
        unknown
            .expect_err("unknown name")
            .to_string()
            .contains("nope")
    );
    let wrong_size = cmd.push_constants(pipeline.layout(), &[0u8; 8]);
    assert!(
        wrong_size
            .expect_err("size")
            .to_string()
            .contains("4 bytes")
    );
    drop(cmd);
    common::assert_clean(&device);
}

#[test]
fn timestamp_scopes_are_ordered_and_named() {
    let device = common::device();
    let timings = device
        .run_once(|cmd| {
            cmd.begin_scope("outer")?;
            cmd.begin_scope("inner")?;
            cmd.end_scope()?;
            cmd.end_scope()
        })
        .expect("submission");
    let names: Vec<_> = timings.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["outer", "inner"]);
    let (outer, inner) = (&timings[0], &timings[1]);
    assert_eq!(
        outer.begin_ns, 0.0,
        "times are relative to the first timestamp"
    );
    assert!(inner.begin_ns >= outer.begin_ns && inner.end_ns <= outer.end_ns);
    assert!(timings.iter().all(|t| t.duration_ns() >= 0.0));
    common::assert_clean(&device);
}

/// The whole of a 256-byte buffer.
const COPY_256: vk::BufferCopy = vk::BufferCopy {
    src_offset: 0,
    dst_offset: 0,
    size: 256,
};

#[test]
fn destruction_waits_for_the_submission_that_may_use_the_object() {
    let device = common::device();
    let usage = vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST;
    let make = |name| common::buffer(&device, name, 256, usage);
    // Nothing in flight: a drop destroys at once.
    drop(make("idle"));
    assert_eq!(device.pending_destructions(), 0);

    let (src, dst) = (make("src"), make("dst"));
    let mut cmd = device.begin_commands().expect("commands");
    // Both buffers are alive when recorded; `src` is dropped before submission on
    // purpose and must survive until the copy has run.
    cmd.copy_buffer(src.raw(), dst.raw(), &[COPY_256]);
    drop(src);
    assert_eq!(
        device.pending_destructions(),
        1,
        "dropped while recorded: deferred"
    );
    let submission = device.submit(cmd).expect("submit");
    assert_eq!(
        device.pending_destructions(),
        1,
        "in flight: still deferred"
    );
    submission.wait().expect("wait");
    assert_eq!(
        device.pending_destructions(),
        0,
        "retired once the fence signalled"
    );
    drop(dst);
    common::assert_clean(&device);
}

#[test]
fn an_object_dropped_during_a_recording_outlives_other_submissions() {
    let device = common::device();
    let usage = vk::BufferUsageFlags::TRANSFER_SRC | vk::BufferUsageFlags::TRANSFER_DST;
    let make = |name| common::buffer(&device, name, 256, usage);
    let (src, dst) = (make("src"), make("dst"));
    let mut frame = device.begin_commands().expect("frame recording");
    // Both buffers are alive when recorded; `src` must survive until the frame runs.
    frame.copy_buffer(src.raw(), dst.raw(), &[COPY_256]);
    drop(src);
    // Another submission (an upload) goes first and completes.
    device.upload_buffer(&dst, 0, &[7u8; 16]).expect("upload");
    // `src` and the upload's staging buffer (dropped while the frame was open, so held too).
    assert_eq!(
        device.pending_destructions(),
        2,
        "still needed by the open recording"
    );
    device.submit(frame).expect("submit").wait().expect("wait");
    assert_eq!(device.pending_destructions(), 0);
    drop(dst);
    common::assert_clean(&device);
}
