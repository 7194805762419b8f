//! A host-visible buffer's mapped bytes are exactly its size, whatever its allocation holds:
//! NVIDIA's driver rounds memory requirements up (a 216-byte staging buffer got 224), and
//! callers copy whole slices into the mapping. Lavapipe allocates exactly what is asked, so
//! only a rounding driver (NVIDIA's) fails this without the fix; the device check runs it there.

mod common;

use common::device;
use shine_gpu::{Buffer, BufferDesc, MemoryLocation, vk};

#[test]
fn mapped_bytes_are_the_buffer_size_not_the_allocation() {
    let device = device();
    for size in [1u64, 13, 216, 1001, 15896] {
        let mut buffer = Buffer::new(
            &device,
            &BufferDesc {
                name: "odd-sized staging",
                size,
                usage: vk::BufferUsageFlags::TRANSFER_SRC,
                location: MemoryLocation::CpuToGpu,
            },
        )
        .expect("buffer");
        assert!(buffer.allocated_bytes() >= size, "size {size}");
        let data: Vec<u8> = (0..size).map(|i| (i * 7 + 3) as u8).collect();
        buffer
            .mapped_mut()
            .expect("host-visible")
            .copy_from_slice(&data);
        assert_eq!(
            buffer.mapped().expect("host-visible"),
            &data[..],
            "size {size}"
        );
    }
}
