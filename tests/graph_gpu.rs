//! The graph on a real device (lavapipe in CI) with the validation layer's synchronization
//! validation on: multi-pass graphs whose readback matches a CPU computation, temporal
//! resources over frames, aliased transients, and bit-identical reruns. Zero messages allowed.
//!
//! Never skips: without a Vulkan device the tests fail (docs/architecture.md, "Tests").

mod common;

use common::{assert_clean, buffer_with, device, read_by_copy};
use shine::gpu::{
    Blend, DepthState, Device, GraphicsPipelineDesc, MemoryLocation, VertexBufferLayout,
};
use shine::graph::vk::{self, AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
use shine::graph::*;
use shine::shaders;

fn readback_buffer(device: &Device, name: &str, size: u64) -> shine::gpu::Buffer {
    let desc = shine::gpu::BufferDesc {
        name,
        size,
        usage: vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST,
        location: MemoryLocation::GpuOnly,
    };
    shine::gpu::Buffer::new(device, &desc).unwrap()
}

fn floats(device: &Device, buffer: &shine::gpu::Buffer) -> Vec<f32> {
    let bytes = device.read_buffer(buffer).unwrap();
    bytes
        .chunks_exact(4)
        .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
        .collect()
}

/// Records one graph into a fresh command buffer, submits it and waits.
fn run(device: &Device, executor: &mut Executor, graph: RenderGraph) -> std::sync::Arc<Plan> {
    let mut commands = device.begin_commands().unwrap();
    let plan = executor.execute(commands.raw(), graph).unwrap();
    device.submit(commands).unwrap().wait().unwrap();
    plan
}

const W: u32 = 16;
const H: u32 = 8;
const TRIANGLES: u32 = 5;

fn splat_pipeline() -> GraphicsPipelineDesc {
    GraphicsPipelineDesc {
        vertex: &shaders::TESTS_GRAPH_SPLAT_VERT,
        fragment: Some(&shaders::TESTS_GRAPH_SPLAT_FRAG),
        vertex_buffers: vec![VertexBufferLayout {
            stride: 16,
            per_instance: false,
            attributes: vec![(0, 0)],
        }],
        topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        cull_mode: vk::CullModeFlags::NONE,
        color_targets: vec![(vk::Format::R32G32B32A32_SFLOAT, Blend::Additive)],
        depth: Some(DepthState {
            format: vk::Format::D32_SFLOAT,
            compare: vk::CompareOp::ALWAYS,
            write: false,
        }),
        depth_bias: None,
    }
}

/// The work the splat graph's `gather` declares (the others declare none): every timing of it
/// carries it.
const GATHER_COST: PassCost = PassCost {
    flops: 8 * (W * H) as u64,
    bytes: 32 * (W * H) as u64,
};

/// compute (emit triangles) → raster (additive splats) → compute (gather into a buffer).
fn splat_graph(executor: &Executor, result: &shine::gpu::Buffer) -> RenderGraph {
    let mut rg = executor.begin_frame();
    let mut vertices = rg.create_buffer("vertices", BufferDesc::new(u64::from(TRIANGLES) * 3 * 16));
    let mut splats = rg.create_image(
        "splats",
        ImageDesc::new_2d(vk::Format::R32G32B32A32_SFLOAT, W, H),
    );
    // Used by the raster pass only: its store op becomes DONT_CARE.
    let mut depth = rg.create_image(
        "splat_depth",
        ImageDesc::new_2d(vk::Format::D32_SFLOAT, W, H),
    );
    let mut out = rg.import_gpu_buffer(result, ExternalState::UNDEFINED, read_by_copy());
    rg.compute("emit", &shaders::TESTS_GRAPH_EMIT_COMP)
        .write("vertices", &mut vertices)
        .push(&TRIANGLES)
        .dispatch([TRIANGLES, 1, 1]);
    rg.raster("splat", splat_pipeline())
        .color(&mut splats, ColorLoad::Clear([0.0; 4]))
        .depth(&mut depth, DepthLoad::Clear(1.0))
        .vertex_buffer(&vertices)
        .draw(3 * TRIANGLES, 1);
    rg.compute("gather", &shaders::TESTS_GRAPH_GATHER_COMP)
        .read("splats", &splats)
        .write("result", &mut out)
        .push(&[W, H])
        .cost(GATHER_COST)
        .dispatch([W, H, 1]);
    rg
}

/// Whether `timings` carry the declared cost of `gather` and none for the other passes.
fn costs_follow_the_passes(timings: &[PassTiming]) -> bool {
    timings.iter().all(|t| {
        t.cost
            == match t.name.as_str() {
                "gather" => Some(GATHER_COST),
                _ => None,
            }
    })
}

/// What the splat graph computes, on the CPU.
fn splat_expected() -> Vec<f32> {
    let sum: f32 = (1..=TRIANGLES).map(|t| t as f32).sum();
    let mut out = Vec::new();
    for y in 0..H {
        for x in 0..W {
            let texel = [
                sum,
                sum * (x as f32 + 0.5),
                sum * (y as f32 + 0.5),
                TRIANGLES as f32,
            ];
            out.extend(texel.map(|c| 2.0 * c + 1.0));
        }
    }
    out
}

#[test]
fn compute_raster_compute_matches_the_cpu_and_reruns_bit_identically() {
    let device = device();
    let result = readback_buffer(&device, "result", u64::from(W * H) * 16);
    let mut executor = Executor::new(&device, 2).unwrap();

    let graph = splat_graph(&executor, &result);
    let plan = run(&device, &mut executor, graph);
    assert_eq!(plan.order(), ["emit", "splat", "gather"]);
    let first = floats(&device, &result);
    assert_eq!(first, splat_expected());

    // Same frame again: the cached plan, the same transients, the same bits.
    let graph = splat_graph(&executor, &result);
    let again = run(&device, &mut executor, graph);
    assert!(std::sync::Arc::ptr_eq(&plan, &again));
    assert_eq!(executor.compiler().compilations(), 1);
    let second = floats(&device, &result);
    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(&first), bits(&second));

    let timings = executor.timings().unwrap();
    let names: Vec<(&str, u64)> = timings.iter().map(|t| (t.name.as_str(), t.frame)).collect();
    assert_eq!(
        names,
        [
            ("emit", 0),
            ("splat", 0),
            ("gather", 0),
            ("emit", 1),
            ("splat", 1),
            ("gather", 1)
        ]
    );
    assert!(timings.iter().all(|t| t.end_ns >= t.begin_ns));
    assert!(costs_follow_the_passes(&timings), "{timings:?}");
    assert_clean(&device);
}

/// The same graph run one pass per submission: the same result, host times in pass order that
/// do not overlap, and no GPU timestamps left to read for that frame.
#[test]
fn serialized_execution_computes_the_same_and_times_each_pass() {
    let device = device();
    let result = readback_buffer(&device, "result", u64::from(W * H) * 16);
    let mut executor = Executor::new(&device, 2).unwrap();
    let graph = splat_graph(&executor, &result);
    let (plan, timings) = executor.execute_serialized(graph).unwrap();
    assert_eq!(plan.order(), ["emit", "splat", "gather"]);
    assert_eq!(floats(&device, &result), splat_expected());
    let names: Vec<&str> = timings.iter().map(|t| t.name.as_str()).collect();
    assert_eq!(names, ["emit", "splat", "gather"]);
    assert!(costs_follow_the_passes(&timings), "{timings:?}");
    for pair in timings.windows(2) {
        assert!(pair[0].begin_ns <= pair[0].end_ns && pair[0].end_ns <= pair[1].begin_ns);
    }
    assert!(executor.timings().unwrap().is_empty());
    assert_clean(&device);
}

const N: u32 = 64;

#[test]
fn a_history_buffer_accumulates_over_three_frames() {
    let device = device();
    let readback = readback_buffer(&device, "readback", u64::from(N) * 4);
    let mut executor = Executor::new(&device, 2).unwrap();
    let mut expected = vec![0.0f32; N as usize];
    for frame in 0..3u32 {
        let mut rg = executor.begin_frame();
        let history = rg.history_buffer("acc", BufferDesc::new(u64::from(N) * 4));
        let mut current = history.current;
        let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
        rg.compute("accumulate", &shaders::TESTS_GRAPH_ACCUMULATE_COMP)
            .read("previous", &history.previous)
            .write("current", &mut current)
            .push(&[N, frame, u32::from(frame > 0)])
            .dispatch([N, 1, 1]);
        rg.copy_buffer("copy_out", &current, &mut out);
        run(&device, &mut executor, rg);
        for (i, e) in expected.iter_mut().enumerate() {
            *e += ((frame + 1) * i as u32) as f32;
        }
        assert_eq!(floats(&device, &readback), expected, "frame {frame}");
    }
    assert_clean(&device);
}

#[test]
fn aliased_transients_in_a_chain_compute_the_right_sum() {
    let device = device();
    let readback = readback_buffer(&device, "readback", u64::from(N) * 4);
    let mut executor = Executor::new(&device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let desc = BufferDesc::new(u64::from(N) * 4);
    let mut chain: Vec<Handle<Buffer>> = (0..4)
        .map(|i| rg.create_buffer(&format!("t{i}"), desc))
        .collect();
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    rg.fill_buffer("zero", &mut chain[0], 0);
    for step in 0..3u32 {
        let previous = chain[step as usize];
        rg.compute(
            &format!("step{step}"),
            &shaders::TESTS_GRAPH_ACCUMULATE_COMP,
        )
        .read("previous", &previous)
        .write("current", &mut chain[step as usize + 1])
        .push(&[N, step, 1])
        .dispatch([N, 1, 1]);
    }
    rg.copy_buffer("copy_out", &chain[3], &mut out);
    let plan = run(&device, &mut executor, rg);
    assert!(plan.memory.saved_bytes() > 0, "{:?}", plan.memory);
    let expected: Vec<f32> = (0..N).map(|i| (6 * i) as f32).collect();
    assert_eq!(floats(&device, &readback), expected);
    assert_clean(&device);
}

/// The harness can see a hazard: two fills of one buffer with no barrier between them inside
/// a raw pass are reported by synchronization validation (when the layer is present).
#[test]
fn synchronization_validation_sees_a_missing_barrier() {
    let device = device();
    let target = readback_buffer(&device, "target", 256);
    let mut executor = Executor::new(&device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let mut out = rg.import_gpu_buffer(&target, ExternalState::UNDEFINED, read_by_copy());
    let written = out;
    rg.raw_pass("fill_twice", move |ctx| {
        if let Some(buffer) = ctx.buffer(&written) {
            // SAFETY: the buffer is alive and the command buffer is recording.
            unsafe {
                ctx.device
                    .raw()
                    .cmd_fill_buffer(ctx.cb, buffer, 0, vk::WHOLE_SIZE, 1);
                ctx.device
                    .raw()
                    .cmd_fill_buffer(ctx.cb, buffer, 0, vk::WHOLE_SIZE, 2);
            }
        }
        Ok(())
    })
    .write(&mut out, BufferAccess::Fill);
    run(&device, &mut executor, rg);
    device.wait_idle().unwrap();
    if device.info().validation {
        assert!(
            device.message_counts().problems() > 0,
            "a write-after-write without a barrier went unreported"
        );
    }
}

#[test]
fn a_pass_run_every_other_frame_keeps_its_output_in_between() {
    let device = device();
    let readback = readback_buffer(&device, "readback", 16);
    let mut executor = Executor::new(&device, 2).unwrap();
    let mut seen = Vec::new();
    for frame in 0..4u32 {
        let mut rg = executor.begin_frame();
        let mut cache = rg.temporal_buffer("cache", BufferDesc::new(16));
        let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
        rg.fill_buffer("slow", &mut cache, frame + 1)
            .run_every(2, 0);
        rg.copy_buffer("use", &cache, &mut out);
        let plan = run(&device, &mut executor, rg);
        let skipped = frame % 2 == 1;
        assert_eq!(plan.skipped.len(), usize::from(skipped), "frame {frame}");
        let bytes = device.read_buffer(&readback).unwrap();
        seen.push(u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]));
    }
    assert_eq!(seen, [1, 1, 3, 3]);
    assert_clean(&device);
}

#[test]
fn aliased_images_through_clear_blits_and_copy() {
    let device = device();
    let (w, h) = (8u32, 4u32);
    let readback = readback_buffer(&device, "readback", u64::from(w * h) * 4);
    let mut executor = Executor::new(&device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let desc = ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, w, h);
    let mut a = rg.create_image("a", desc);
    let mut b = rg.create_image("b", desc);
    let mut c = rg.create_image("c", desc);
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    rg.clear_image("clear_a", &mut a, [1.0, 0.0, 1.0, 0.0]);
    rg.blit_image("a_to_b", &a, &mut b, vk::Filter::NEAREST);
    rg.blit_image("b_to_c", &b, &mut c, vk::Filter::NEAREST);
    rg.copy_image_to_buffer("c_out", &c, &mut out);
    let plan = run(&device, &mut executor, rg);
    let (pa, pc) = (
        plan.memory.placement(a.id()).unwrap(),
        plan.memory.placement(c.id()).unwrap(),
    );
    assert!(
        pa.overlaps_memory(pc),
        "c should reuse a's memory: {:?}",
        plan.memory
    );
    let bytes = device.read_buffer(&readback).unwrap();
    assert!(bytes.chunks_exact(4).all(|t| t == [255, 0, 255, 0]));
    assert_clean(&device);
}

/// Depth-only pipeline of `graph_depth.vert` over vec4 positions.
fn depth_pipeline() -> GraphicsPipelineDesc {
    GraphicsPipelineDesc {
        vertex: &shaders::TESTS_GRAPH_DEPTH_VERT,
        fragment: None,
        vertex_buffers: vec![VertexBufferLayout {
            stride: 16,
            per_instance: false,
            attributes: vec![(0, 0)],
        }],
        topology: vk::PrimitiveTopology::TRIANGLE_LIST,
        cull_mode: vk::CullModeFlags::NONE,
        color_targets: Vec::new(),
        depth: Some(DepthState {
            format: vk::Format::D32_SFLOAT,
            compare: vk::CompareOp::LESS,
            write: true,
        }),
        depth_bias: None,
    }
}

/// A far full-screen triangle, then a near one (clip space, vec4 positions), and their indices.
fn far_then_near(far: f32, near: f32) -> (Vec<f32>, Vec<u32>) {
    let mut positions: Vec<f32> = Vec::new();
    for z in [far, near] {
        for (x, y) in [(-1.0, -1.0), (3.0, -1.0), (-1.0, 3.0)] {
            positions.extend([x, y, z, 0.0]);
        }
    }
    (positions, vec![0, 1, 2, 3, 4, 5])
}

/// Two raster passes into the two halves of one depth image (an atlas of two tiles): each
/// clears and draws only inside its area, so the first tile survives the second pass's clear;
/// an area outside the attachment is an error, not a Vulkan fault.
#[test]
fn raster_areas_render_tiles_of_one_attachment() {
    let device = device();
    let (w, h) = (8u32, 8u32);
    let (far, near) = (0.75f32, 0.25f32);
    let (positions, index_data) = far_then_near(far, near);
    let vertices = buffer_with(
        &device,
        "vertices",
        vk::BufferUsageFlags::VERTEX_BUFFER,
        bytemuck::cast_slice(&positions),
    );
    let indices = buffer_with(
        &device,
        "indices",
        vk::BufferUsageFlags::INDEX_BUFFER,
        bytemuck::cast_slice(&index_data),
    );
    let readback = readback_buffer(&device, "readback", u64::from(w * h) * 4);
    let sampler = shine::gpu::Sampler::new(&device, &vk::SamplerCreateInfo::default()).unwrap();
    let uploaded_state = ExternalState::new(S::COPY, A::TRANSFER_WRITE, L::UNDEFINED);
    let mut executor = Executor::new(&device, 1).unwrap();
    let graph = |executor: &Executor, right_offset: u32| {
        let mut rg = executor.begin_frame();
        let vb = rg.import_gpu_buffer(&vertices, uploaded_state, ExternalState::UNDEFINED);
        let ib = rg.import_gpu_buffer(&indices, uploaded_state, ExternalState::UNDEFINED);
        let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
        let mut depth = rg.create_image("atlas", ImageDesc::new_2d(vk::Format::D32_SFLOAT, w, h));
        rg.raster("left tile", depth_pipeline())
            .depth(&mut depth, DepthLoad::Clear(1.0))
            .area([0, 0], [w / 2, h])
            .vertex_buffer(&vb)
            .index_buffer(&ib, vk::IndexType::UINT32)
            .draw_indexed(3, 1);
        rg.raster("right tile", depth_pipeline())
            .depth(&mut depth, DepthLoad::Clear(1.0))
            .area([right_offset, 0], [w / 2, h])
            .vertex_buffer(&vb)
            .index_buffer(&ib, vk::IndexType::UINT32)
            .draw_indexed(6, 1);
        rg.compute("read_depth", &shaders::TESTS_GRAPH_DEPTH_READ_COMP)
            .read("depth", &depth)
            .sampler("nearest", sampler.raw())
            .write("result", &mut out)
            .push(&[w, h])
            .dispatch([w, h, 1]);
        rg
    };
    let tiles = graph(&executor, w / 2);
    run(&device, &mut executor, tiles);
    let depths = floats(&device, &readback);
    for (i, d) in depths.iter().enumerate() {
        let expected = if (i as u32 % w) < w / 2 { far } else { near };
        assert_eq!(*d, expected, "texel {i}");
    }
    let mut commands = device.begin_commands().unwrap();
    let outside = graph(&executor, w / 2 + 1);
    let err = executor.execute(commands.raw(), outside).unwrap_err();
    drop(commands);
    assert!(
        err.to_string().contains("outside its 8×8 attachments"),
        "{err}"
    );
    assert_clean(&device);
}

#[test]
fn indexed_depth_pass_then_sampled_in_compute() {
    let device = device();
    let (w, h) = (8u32, 8u32);
    // A far triangle, then a near one over it: the depth test keeps the near depth.
    let (far, near) = (0.75f32, 0.25f32);
    let (positions, index_data) = far_then_near(far, near);
    let vertices = buffer_with(
        &device,
        "vertices",
        vk::BufferUsageFlags::VERTEX_BUFFER,
        bytemuck::cast_slice(&positions),
    );
    let indices = buffer_with(
        &device,
        "indices",
        vk::BufferUsageFlags::INDEX_BUFFER,
        bytemuck::cast_slice(&index_data),
    );
    let readback = readback_buffer(&device, "readback", u64::from(w * h) * 4);
    let sampler = shine::gpu::Sampler::new(&device, &vk::SamplerCreateInfo::default()).unwrap();
    let uploaded_state = ExternalState::new(S::COPY, A::TRANSFER_WRITE, L::UNDEFINED);

    let mut executor = Executor::new(&device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let vb = rg.import_gpu_buffer(&vertices, uploaded_state, ExternalState::UNDEFINED);
    let ib = rg.import_gpu_buffer(&indices, uploaded_state, ExternalState::UNDEFINED);
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    let mut depth = rg.create_image("depth", ImageDesc::new_2d(vk::Format::D32_SFLOAT, w, h));
    let pipeline = depth_pipeline();
    rg.raster("depth_only", pipeline)
        .depth(&mut depth, DepthLoad::Clear(1.0))
        .vertex_buffer(&vb)
        .index_buffer(&ib, vk::IndexType::UINT32)
        .draw_indexed(6, 1);
    rg.compute("read_depth", &shaders::TESTS_GRAPH_DEPTH_READ_COMP)
        .read("depth", &depth)
        .sampler("nearest", sampler.raw())
        .write("result", &mut out)
        .push(&[w, h])
        .dispatch([w, h, 1]);
    let plan = run(&device, &mut executor, rg);
    assert_eq!(
        plan.barriers_before("read_depth")[0].new_layout,
        L::SHADER_READ_ONLY_OPTIMAL
    );
    assert!(floats(&device, &readback).iter().all(|&d| d == near));
    assert_clean(&device);
}

/// Frame `frame`: fill a transient with `frame + 1`, then a raw pass copies it into `readback`
/// and notes which Vulkan buffer the transient was.
fn fill_through_a_transient(
    executor: &Executor,
    readback: &shine::gpu::Buffer,
    seen: &std::rc::Rc<std::cell::RefCell<Vec<vk::Buffer>>>,
) -> RenderGraph {
    let mut rg = executor.begin_frame();
    let value = executor.frame() as u32 + 1;
    let mut scratch = rg.create_buffer("scratch", BufferDesc::new(16));
    let mut out = rg.import_gpu_buffer(readback, ExternalState::UNDEFINED, read_by_copy());
    rg.fill_buffer("fill", &mut scratch, value);
    let (src, dst, seen) = (scratch, out, std::rc::Rc::clone(seen));
    rg.raw_pass("copy_out", move |ctx| {
        if let (Some(src), Some(dst)) = (ctx.buffer(&src), ctx.buffer(&dst)) {
            seen.borrow_mut().push(src);
            let region = vk::BufferCopy {
                src_offset: 0,
                dst_offset: 0,
                size: 16,
            };
            // SAFETY: both buffers live for the frame; the graph put them in copy scope.
            unsafe {
                ctx.device
                    .raw()
                    .cmd_copy_buffer(ctx.cb, src, dst, &[region])
            };
        }
        Ok(())
    })
    .read(&scratch, BufferAccess::CopySrc)
    .write(&mut out, BufferAccess::CopyDst);
    rg
}

#[test]
fn frames_in_flight_never_share_transient_memory() {
    let device = device();
    // One name for both, so that every frame has the same shape (and plan).
    let readbacks = [
        readback_buffer(&device, "readback", 16),
        readback_buffer(&device, "readback", 16),
    ];
    let seen = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
    let mut executor = Executor::new(&device, 2).unwrap();
    // Frames 0 and 1 are both submitted before either is waited for.
    let mut submissions = Vec::new();
    for readback in &readbacks {
        let graph = fill_through_a_transient(&executor, readback, &seen);
        let mut commands = device.begin_commands().unwrap();
        executor.execute(commands.raw(), graph).unwrap();
        submissions.push(device.submit(commands).unwrap());
    }
    for s in submissions {
        s.wait().unwrap();
    }
    let first = |b: &shine::gpu::Buffer| {
        let bytes = device.read_buffer(b).unwrap();
        u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
    };
    assert_eq!([first(&readbacks[0]), first(&readbacks[1])], [1, 2]);
    // Frame 2 (frame 0 has completed) takes frame 0's slot and its transients back.
    let graph = fill_through_a_transient(&executor, &readbacks[0], &seen);
    run(&device, &mut executor, graph);
    assert_eq!(first(&readbacks[0]), 3);
    let seen = seen.borrow();
    assert_ne!(seen[0], seen[1], "frames 0 and 1 shared a transient");
    assert_eq!(seen[2], seen[0]);
    assert_eq!(executor.compiler().compilations(), 1);
    assert_clean(&device);
}

#[test]
fn a_temporal_no_pass_touches_is_not_created() {
    let device = device();
    let readback = readback_buffer(&device, "readback", 16);
    let mut executor = Executor::new(&device, 1).unwrap();
    let mut rg = executor.begin_frame();
    let idle = rg.temporal_image("idle", ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, 4, 4));
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    rg.fill_buffer("fill", &mut out, 7);
    let plan = run(&device, &mut executor, rg);
    assert!(!plan.resource(idle.id()).unwrap().used);
    assert_eq!(device.read_buffer(&readback).unwrap()[0], 7);
    assert_clean(&device);
}

#[test]
fn a_pipeline_that_fails_leaves_the_command_buffer_untouched() {
    let device = device();
    let readback = readback_buffer(&device, "readback", u64::from(W * H) * 16);
    let mut executor = Executor::new(&device, 1).unwrap();
    // A raw pass first, then a raster pass whose pipeline has an attribute at a location its
    // vertex shader lacks: creating that pipeline fails.
    let mut broken = splat_pipeline();
    broken.vertex_buffers[0].attributes = vec![(7, 0)];
    broken.depth = None;
    let recorded = std::rc::Rc::new(std::cell::Cell::new(false));
    let mut rg = executor.begin_frame();
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    let flag = std::rc::Rc::clone(&recorded);
    rg.raw_pass("mark", move |_| {
        flag.set(true);
        Ok(())
    })
    .write(&mut out, BufferAccess::Fill);
    let mut splats = rg.create_image(
        "splats",
        ImageDesc::new_2d(vk::Format::R32G32B32A32_SFLOAT, W, H),
    );
    rg.raster("splat", broken)
        .color(&mut splats, ColorLoad::Clear([0.0; 4]))
        .draw(3, 1);
    rg.compute("gather", &shaders::TESTS_GRAPH_GATHER_COMP)
        .read("splats", &splats)
        .write("result", &mut out)
        .push(&[W, H])
        .dispatch([W, H, 1]);
    let mut commands = device.begin_commands().unwrap();
    let error = executor.execute(commands.raw(), rg).unwrap_err();
    assert!(
        matches!(error, ExecuteError::Gpu(shine::gpu::Error::Binding { .. })),
        "{error}"
    );
    assert!(!recorded.get(), "a pass was recorded before the failure");
    assert_eq!(executor.frame(), 0);
    // Nothing was recorded: submitting the empty recording is valid.
    device.submit(commands).unwrap().wait().unwrap();
    let mut rg = executor.begin_frame();
    let mut out = rg.import_gpu_buffer(&readback, ExternalState::UNDEFINED, read_by_copy());
    rg.fill_buffer("fill", &mut out, 2);
    run(&device, &mut executor, rg);
    assert_eq!(device.read_buffer(&readback).unwrap()[0], 2);
    assert_eq!(executor.timings().unwrap().len(), 1);
    assert_clean(&device);
}
