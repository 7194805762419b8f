//! Transient aliasing and temporal resources, on fixture graphs (no GPU).

mod common;

use common::*;
use shine_graph::vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
use shine_graph::*;

/// Lifetimes recomputed from the planned passes: first and last position using each resource.
fn lifetimes(plan: &Plan) -> Vec<Option<(usize, usize)>> {
    let mut out = vec![None; plan.resources.len()];
    for (pos, pass) in plan.passes.iter().enumerate() {
        for r in &pass.resources {
            let l: &mut Option<(usize, usize)> = &mut out[r.resource.0 as usize];
            *l = Some(l.map_or((pos, pos), |(first, _)| (first, pos)));
        }
    }
    out
}

/// No two placements share memory while both are alive, and each placement's lifetime is the
/// real one.
fn assert_no_live_overlap(plan: &Plan) {
    let real = lifetimes(plan);
    let ps = &plan.memory.placements;
    for p in ps {
        assert_eq!(Some(p.lifetime), real[p.resource.0 as usize], "{p:?}");
        assert!(p.offset + p.size <= plan.memory.heaps[p.heap].size);
    }
    for (i, a) in ps.iter().enumerate() {
        for b in &ps[i + 1..] {
            assert!(
                !(a.overlaps_memory(b) && a.overlaps_lifetime(b)),
                "{a:?} and {b:?} overlap while both alive"
            );
        }
    }
}

#[test]
fn a_chain_of_transients_reuses_memory_and_waits_for_the_previous_tenant() {
    let mut rg = RenderGraph::new(0);
    let mut t: Vec<Handle<Image>> = (0..4)
        .map(|i| rg.create_image(&format!("t{i}"), image()))
        .collect();
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("p0", PassKind::Compute)
        .write(&mut t[0], ImageAccess::StorageWriteCompute);
    for i in 1..4 {
        let prev = t[i - 1];
        rg.pass(&format!("p{i}"), PassKind::Compute)
            .read(&prev, ImageAccess::SampledCompute)
            .write(&mut t[i], ImageAccess::StorageWriteCompute);
    }
    rg.pass("last", PassKind::Compute)
        .read(&t[3], ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_no_live_overlap(&plan);
    let size = 64 * 64 * 4;
    assert_eq!(plan.memory.requested_bytes, 4 * size);
    assert_eq!(plan.memory.allocated_bytes, 2 * size);
    assert_eq!(plan.memory.saved_bytes(), 2 * size);
    let p = |i: usize| *plan.memory.placement(t[i].id()).unwrap();
    assert!(p(2).overlaps_memory(&p(0)));
    // t2 takes t0's memory: its first barrier waits for t0's last reader (p1).
    assert_eq!(
        plan.barriers_before("p2")[1],
        barrier(
            t[2].id(),
            (S::COMPUTE_SHADER, A::NONE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (L::UNDEFINED, L::GENERAL),
        )
    );
}

/// A tiny deterministic generator (no dependency needed).
struct Lcg(u64);

impl Lcg {
    fn next(&mut self, n: usize) -> usize {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 33) % n as u64) as usize
    }
}

#[test]
fn aliasing_never_overlaps_two_live_resources_on_random_graphs() {
    let mut rng = Lcg(7);
    let mut total_saved = 0;
    for graph in 0..200 {
        let mut rg = RenderGraph::new(0);
        let mut written: Vec<Handle<Buffer>> = Vec::new();
        let mut out = output_buffer(&mut rg, "out");
        let passes = 2 + rng.next(12);
        for p in 0..passes {
            let size = 256 * (1 + rng.next(16) as u64);
            let mut fresh = rg.create_buffer(&format!("b{p}"), BufferDesc::new(size));
            let reads: Vec<Handle<Buffer>> = (0..rng.next(3))
                .filter(|_| !written.is_empty())
                .map(|_| written[rng.next(written.len())])
                .collect();
            let mut pass = rg.pass(&format!("p{p}"), PassKind::Compute);
            for r in &reads {
                pass.read(r, BufferAccess::StorageReadCompute);
            }
            pass.write(&mut fresh, BufferAccess::StorageWriteCompute);
            if rng.next(3) == 0 {
                pass.write(&mut out, BufferAccess::StorageReadWriteCompute);
            }
            written.push(fresh);
        }
        let last = written[written.len() - 1];
        rg.pass("final", PassKind::Compute)
            .read(&last, BufferAccess::StorageReadCompute)
            .write(&mut out, BufferAccess::StorageReadWriteCompute);
        let plan = compile(&rg).unwrap_or_else(|e| panic!("graph {graph}: {e}"));
        assert_no_live_overlap(&plan);
        assert_eq!(
            plan.memory.requested_bytes - plan.memory.allocated_bytes,
            plan.memory.saved_bytes()
        );
        total_saved += plan.memory.saved_bytes();
    }
    assert!(total_saved > 0);
}

/// Frame `frame` of a ping-pong accumulation: read last frame's sum, write this frame's, copy it
/// out.
fn accumulate(frame: u64) -> (RenderGraph, History<Image>) {
    let mut rg = RenderGraph::new(frame);
    let h = rg.history_image("sum", image());
    let mut cur = h.current;
    let mut out = rg.import_buffer(
        "readback",
        BufferDesc::new(64 * 64 * 4),
        BufferImport {
            initial: ExternalState::UNDEFINED,
            final_state: ExternalState::new(S::HOST, A::HOST_READ, L::UNDEFINED),
            usage: vk::BufferUsageFlags::TRANSFER_DST,
            read_only: false,
        },
    );
    rg.pass("accumulate", PassKind::Compute)
        .read(&h.previous, ImageAccess::SampledCompute)
        .write(&mut cur, ImageAccess::StorageWriteCompute);
    rg.pass("copy_out", PassKind::Transfer)
        .read(&cur, ImageAccess::CopySrc)
        .write(&mut out, BufferAccess::CopyDst);
    (rg, h)
}

#[test]
fn history_pairs_carry_layouts_and_hazards_across_frames() {
    let mut compiler = Compiler::new();
    let mut plans = Vec::new();
    for frame in 0..6 {
        let (rg, h) = accumulate(frame);
        let plan = compiler.compile(&rg, &FakeMemory).unwrap();
        compiler.finish_frame(&plan);
        plans.push((plan, h));
    }
    assert!(compiler.has_history("sum#0", image()) && compiler.has_history("sum#1", image()));
    // Frame 0: both halves are fresh.
    let (plan, h) = &plans[0];
    assert_eq!(
        plan.barriers_before("accumulate"),
        [
            barrier(
                h.previous.id(),
                (S::NONE, A::NONE),
                (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
                (L::UNDEFINED, L::SHADER_READ_ONLY_OPTIMAL),
            ),
            barrier(
                h.current.id(),
                (S::NONE, A::NONE),
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
                (L::UNDEFINED, L::GENERAL),
            ),
        ]
    );
    assert_eq!(
        plan.final_barriers,
        [barrier(
            ResourceId(2),
            (S::COPY, A::TRANSFER_WRITE),
            (S::HOST, A::HOST_READ),
            (L::UNDEFINED, L::UNDEFINED),
        )]
    );
    // Frames 1 and later: last frame's current (left in TRANSFER_SRC by the copy) is read,
    // last frame's previous (left SHADER_READ_ONLY) is overwritten after its reader.
    for (plan, h) in &plans[1..] {
        assert_eq!(
            plan.barriers_before("accumulate"),
            [
                barrier(
                    h.previous.id(),
                    (S::COPY, A::NONE),
                    (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
                    (L::TRANSFER_SRC_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
                ),
                barrier(
                    h.current.id(),
                    (S::COMPUTE_SHADER, A::NONE),
                    (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
                    (L::SHADER_READ_ONLY_OPTIMAL, L::GENERAL),
                ),
            ]
        );
    }
    // Both halves have the union of both roles' usage, so swapping never recreates them.
    use vk::ImageUsageFlags as U;
    let usage = Usage::Image(U::SAMPLED | U::STORAGE | U::TRANSFER_SRC);
    assert!(plans.iter().all(|(p, h)| {
        p.resource(h.previous.id()).unwrap().usage == usage
            && p.resource(h.current.id()).unwrap().usage == usage
    }));
    // Frames 0 to 3 differ in the state they inherit (a half first seen fresh carries less
    // history); from frame 4 on the two alternating steady-state plans come from the cache.
    assert_eq!(compiler.compilations(), 4);
}

#[test]
fn a_periodic_pass_is_skipped_and_its_output_persists() {
    let graph = |frame| {
        let mut rg = RenderGraph::new(frame);
        let mut cache = rg.temporal_image("gi_cache", image());
        let mut out = output_buffer(&mut rg, "out");
        rg.pass("gi", PassKind::Compute)
            .write(&mut cache, ImageAccess::StorageWriteCompute)
            .run_every(2, 0);
        rg.pass("shade", PassKind::Compute)
            .read(&cache, ImageAccess::SampledCompute)
            .write(&mut out, BufferAccess::StorageWriteCompute);
        (rg, cache)
    };
    let mut compiler = Compiler::new();
    let mut plans = Vec::new();
    for frame in 0..3 {
        let (rg, cache) = graph(frame);
        let plan = compiler.compile(&rg, &FakeMemory).unwrap();
        compiler.finish_frame(&plan);
        plans.push((plan, cache));
    }
    assert_eq!(plans[0].0.order(), ["gi", "shade"]);
    assert!(plans[0].0.skipped.is_empty());
    let (plan, cache) = &plans[1];
    assert_eq!(plan.order(), ["shade"]);
    assert_eq!(plan.skipped, ["gi"]);
    // The cache stays SHADER_READ_ONLY; the read still waits for frame 0's write.
    assert_eq!(
        plan.barriers_before("shade"),
        [barrier(
            cache.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            (L::SHADER_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
    let (plan, cache) = &plans[2];
    assert_eq!(plan.order(), ["gi", "shade"]);
    assert_eq!(
        plan.barriers_before("gi"),
        [barrier(
            cache.id(),
            (S::COMPUTE_SHADER, A::NONE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (L::SHADER_READ_ONLY_OPTIMAL, L::GENERAL),
        )]
    );
}

#[test]
fn alignment_padding_saves_nothing_and_dumps_fine() {
    // Two 100-byte buffers alive together at 256-byte alignment: the heap (356 bytes) is larger
    // than the 200 bytes requested.
    let mut rg = RenderGraph::new(0);
    let mut a = rg.create_buffer("a", BufferDesc::new(100));
    let mut b = rg.create_buffer("b", BufferDesc::new(100));
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("fill", PassKind::Compute)
        .write(&mut a, BufferAccess::StorageWriteCompute)
        .write(&mut b, BufferAccess::StorageWriteCompute);
    rg.pass("use", PassKind::Compute)
        .read(&a, BufferAccess::StorageReadCompute)
        .read(&b, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_no_live_overlap(&plan);
    assert_eq!(plan.memory.requested_bytes, 200);
    assert_eq!(plan.memory.allocated_bytes, 356);
    assert_eq!(plan.memory.saved_bytes(), 0);
    let dump = plan.dump();
    assert!(dump.json.contains("\"saved_bytes\": 0"), "{}", dump.json);
}

/// One frame of a cache that a pass writes every other frame (on odd frames) at `size`×`size`,
/// and that a second pass reads every frame.
fn periodic_cache(frame: u64, size: u32) -> RenderGraph {
    let mut rg = RenderGraph::new(frame);
    let desc = ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, size, size);
    let mut cache = rg.temporal_image("cache", desc);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("gi", PassKind::Compute)
        .write(&mut cache, ImageAccess::StorageWriteCompute)
        .run_every(2, 1);
    rg.pass("shade", PassKind::Compute)
        .read(&cache, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg
}

#[test]
fn history_exists_only_once_written_with_the_same_description() {
    let small = ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, 32, 32);
    let mut compiler = Compiler::new();
    let run = |compiler: &mut Compiler, frame: u64, size: u32| {
        let plan = compiler
            .compile(&periodic_cache(frame, size), &FakeMemory)
            .unwrap();
        compiler.finish_frame(&plan);
    };
    // Frame 0: the writer does not run yet; the cache exists but holds nothing.
    run(&mut compiler, 0, 64);
    assert!(!compiler.has_history("cache", image()));
    // Frame 1: written.
    run(&mut compiler, 1, 64);
    assert!(compiler.has_history("cache", image()));
    assert!(!compiler.has_history("cache", small));
    assert!(!compiler.has_history("other", image()));
    // Frame 2: the writer skips; the contents persist.
    run(&mut compiler, 2, 64);
    assert!(compiler.has_history("cache", image()));
    // Frame 4: resized on a frame its writer skips: recreated, undefined again.
    run(&mut compiler, 4, 32);
    assert!(!compiler.has_history("cache", small));
    assert!(!compiler.has_history("cache", image()));
    // Frame 5: written at the new size.
    run(&mut compiler, 5, 32);
    assert!(compiler.has_history("cache", small));
}

#[test]
fn a_temporal_no_pass_touches_keeps_its_history() {
    let graph = |frame, touch: bool| {
        let mut rg = RenderGraph::new(frame);
        let mut cache = rg.temporal_image("cache", image());
        let mut out = output_buffer(&mut rg, "out");
        if touch {
            rg.pass("gi", PassKind::Compute)
                .write(&mut cache, ImageAccess::StorageWriteCompute);
        }
        rg.pass("shade", PassKind::Compute)
            .write(&mut out, BufferAccess::StorageWriteCompute);
        (rg, cache)
    };
    let mut compiler = Compiler::new();
    let (rg, _) = graph(0, true);
    let written = compiler.compile(&rg, &FakeMemory).unwrap();
    compiler.finish_frame(&written);
    let (rg, cache) = graph(1, false);
    let idle = compiler.compile(&rg, &FakeMemory).unwrap();
    compiler.finish_frame(&idle);
    // Declared but untouched: no usage (the executor creates nothing for it), and what frame 0
    // wrote is still the history.
    let r = idle.resource(cache.id()).unwrap();
    assert_eq!(r.usage, Usage::Image(vk::ImageUsageFlags::empty()));
    assert!(!r.used);
    assert!(compiler.has_history("cache", image()));
    let (rg, cache) = graph(2, true);
    let again = compiler.compile(&rg, &FakeMemory).unwrap();
    // Frame 2 continues from frame 0's state: GENERAL, waiting for its write.
    assert_eq!(
        again.barriers_before("gi"),
        [barrier(
            cache.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (L::GENERAL, L::GENERAL),
        )]
    );
}
