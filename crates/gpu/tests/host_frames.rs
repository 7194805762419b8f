//! Deferred destruction on a host's frame clock (`Device::begin_host_frame`), on a real device
//! (lavapipe in CI) with the validation layer when installed.

mod common;

use common::device;
use shine_gpu::{Buffer, BufferDesc, Device, MemoryLocation, vk};

fn buffer(device: &Device) -> Buffer {
    Buffer::new(
        device,
        &BufferDesc {
            name: "host frame buffer",
            size: 4096,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuOnly,
        },
    )
    .expect("buffer")
}

#[test]
fn a_buffer_dropped_in_host_frame_5_lives_until_frame_7_begins() {
    let device = device();
    // Without the host clock and with nothing submitted, a drop destroys at once.
    drop(buffer(&device));
    assert_eq!(device.pending_destructions(), 0);

    device.begin_host_frame(5, 2);
    let used_by_frame_5 = buffer(&device);
    let bytes = used_by_frame_5.allocated_bytes();
    assert!(bytes >= 4096);
    let before = device.memory_usage();
    drop(used_by_frame_5);
    assert_eq!(device.pending_destructions(), 1, "frame 5 may be in flight");
    assert_eq!(
        device.memory_usage(),
        before,
        "still allocated until destroyed"
    );

    device.begin_host_frame(6, 2);
    assert_eq!(
        device.pending_destructions(),
        1,
        "frame 5 may still be in flight"
    );
    device.retire().expect("retire");
    assert_eq!(
        device.pending_destructions(),
        1,
        "retire respects the host clock"
    );

    device.begin_host_frame(7, 2);
    assert_eq!(device.pending_destructions(), 0, "frame 5 has completed");
    assert_eq!(
        device.memory_usage().allocated_bytes,
        before.allocated_bytes - bytes
    );
    assert_eq!(
        device.message_counts().problems(),
        0,
        "{:?}",
        device.messages()
    );
}

#[test]
fn dropping_the_device_destroys_what_waits_for_host_frames() {
    let device = device();
    device.begin_host_frame(0, 3);
    drop(buffer(&device));
    assert_eq!(device.pending_destructions(), 1);
    assert_eq!(
        device.message_counts().problems(),
        0,
        "{:?}",
        device.messages()
    );
    // The device's drop destroys it (validation would report a leak otherwise).
    drop(device);
}
