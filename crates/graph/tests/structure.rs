//! Culling, ordering, errors, caching and the dumps, on fixture graphs (no GPU).

mod common;

use common::*;
use shine_graph::*;

#[test]
fn passes_that_reach_no_output_are_culled() {
    let mut rg = RenderGraph::new(0);
    let mut used = rg.create_image("used", image());
    let mut dead = rg.create_image("dead", image());
    let mut dead2 = rg.create_buffer("dead2", BufferDesc::new(64));
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("produce", PassKind::Compute)
        .write(&mut used, ImageAccess::StorageWriteCompute);
    rg.pass("orphan", PassKind::Compute)
        .write(&mut dead, ImageAccess::StorageWriteCompute);
    rg.pass("orphan_reader", PassKind::Compute)
        .read(&dead, ImageAccess::SampledCompute)
        .write(&mut dead2, BufferAccess::StorageWriteCompute);
    rg.pass("consume", PassKind::Compute)
        .read(&used, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["produce", "consume"]);
    assert_eq!(plan.culled, ["orphan", "orphan_reader"]);
    assert!(!plan.resource(dead.id()).unwrap().used);
    assert!(plan.memory.placement(dead.id()).is_none());
    assert!(plan.memory.placement(dead2.id()).is_none());
    assert!(plan.memory.placement(used.id()).is_some());
}

#[test]
fn earlier_writers_of_a_kept_resource_are_kept() {
    let mut rg = RenderGraph::new(0);
    let mut img = rg.create_image("img", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("clear", PassKind::Transfer)
        .write(&mut img, ImageAccess::ClearDst);
    rg.pass("splat", PassKind::Raster)
        .write(&mut img, ImageAccess::ColorAttachmentReadWrite);
    rg.pass("resolve", PassKind::Compute)
        .read(&img, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["clear", "splat", "resolve"]);
    assert!(plan.culled.is_empty());
}

#[test]
fn a_stale_read_is_ordered_before_the_overwrite() {
    let mut rg = RenderGraph::new(0);
    let mut cache = rg.temporal_buffer("cache", BufferDesc::new(256));
    let old = cache;
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("update", PassKind::Compute)
        .write(&mut cache, BufferAccess::StorageWriteCompute);
    rg.pass("use_old", PassKind::Compute)
        .read(&old, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["use_old", "update"]);
}

#[test]
fn contradictory_dependencies_are_a_cycle_error() {
    let mut rg = RenderGraph::new(0);
    let mut x = rg.temporal_buffer("x", BufferDesc::new(256));
    let mut y = rg.temporal_buffer("y", BufferDesc::new(256));
    let x0 = x;
    rg.pass("make_y", PassKind::Compute)
        .write(&mut y, BufferAccess::StorageWriteCompute);
    let y1 = y;
    // p1 overwrites x and reads y version 1; p2 reads the old x and overwrites y:
    // p2 must precede p1 (x) and follow it (y).
    rg.pass("p1", PassKind::Compute)
        .read(&y1, BufferAccess::StorageReadCompute)
        .write(&mut x, BufferAccess::StorageWriteCompute);
    rg.pass("p2", PassKind::Compute)
        .read(&x0, BufferAccess::StorageReadCompute)
        .write(&mut y, BufferAccess::StorageWriteCompute);
    let err = compile(&rg).unwrap_err();
    assert_eq!(
        err,
        GraphError::Cycle {
            passes: vec!["p1".into(), "p2".into()]
        }
    );
    assert!(err.to_string().contains("cycle"));
}

#[test]
fn reading_a_never_written_transient_is_an_error() {
    let mut rg = RenderGraph::new(0);
    let img = rg.create_image("img", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("read", PassKind::Compute)
        .read(&img, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    assert_eq!(
        compile(&rg).unwrap_err(),
        GraphError::ReadOfUnwritten {
            pass: "read".into(),
            resource: "img".into(),
            version: 0
        }
    );
}

#[test]
fn writing_a_read_only_import_is_an_error() {
    let mut rg = RenderGraph::new(0);
    let mut input = rg.import_buffer(
        "input",
        BufferDesc::new(64),
        BufferImport {
            initial: ExternalState::UNDEFINED,
            final_state: ExternalState::UNDEFINED,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            read_only: true,
        },
    );
    rg.pass("scribble", PassKind::Compute)
        .write(&mut input, BufferAccess::StorageWriteCompute);
    assert_eq!(
        compile(&rg).unwrap_err(),
        GraphError::WriteToReadOnly {
            pass: "scribble".into(),
            resource: "input".into()
        }
    );
}

#[test]
fn an_import_without_the_needed_usage_is_an_error() {
    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("draw_from", PassKind::Raster)
        .write(&mut out, BufferAccess::Fill)
        .read(&out.clone(), BufferAccess::Vertex);
    let err = compile(&rg).unwrap_err();
    assert!(matches!(err, GraphError::UsageMismatch { .. }), "{err}");
    assert!(err.to_string().contains("VERTEX_BUFFER"), "{err}");
}

#[test]
fn writing_through_an_old_handle_is_an_error() {
    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    let mut old = out;
    rg.pass("a", PassKind::Compute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("b", PassKind::Compute)
        .write(&mut old, BufferAccess::StorageWriteCompute);
    assert_eq!(
        compile(&rg).unwrap_err(),
        GraphError::StaleWrite {
            pass: "b".into(),
            resource: "out".into(),
            version: 0,
            latest: 1
        }
    );
}

#[test]
fn one_image_in_two_layouts_in_one_pass_is_an_error() {
    let mut rg = RenderGraph::new(0);
    let mut img = rg.create_image("img", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("init", PassKind::Compute)
        .write(&mut img, ImageAccess::StorageWriteCompute);
    let before = img;
    rg.pass("both", PassKind::Compute)
        .read(&before, ImageAccess::SampledCompute)
        .write(&mut img, ImageAccess::StorageWriteCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::LayoutConflict { .. }
    ));
}

#[test]
fn other_declaration_mistakes_are_errors() {
    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("same", PassKind::Compute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("same", PassKind::Compute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::DuplicatePassName { .. }
    ));

    let mut rg = RenderGraph::new(0);
    rg.create_image("empty", ImageDesc::new_2d(vk::Format::R8_UNORM, 0, 4));
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::InvalidDescription { .. }
    ));

    let mut rg = RenderGraph::new(0);
    let mut t = rg.create_buffer("t", BufferDesc::new(64));
    rg.pass("slow", PassKind::Compute)
        .write(&mut t, BufferAccess::StorageWriteCompute)
        .run_every(4, 0);
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::PeriodicPassWritesTransient { period: 4, .. }
    ));

    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("never", PassKind::Compute)
        .write(&mut out, BufferAccess::StorageWriteCompute)
        .run_every(0, 0);
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::ZeroPeriod { .. }
    ));
}

#[test]
fn a_handle_from_another_graph_is_an_error() {
    let mut other = RenderGraph::new(0);
    let mut foreign = other.create_buffer("foreign", BufferDesc::new(64));
    for _ in 0..3 {
        other
            .pass(&format!("w{}", foreign.version()), PassKind::Compute)
            .write(&mut foreign, BufferAccess::StorageWriteCompute);
    }
    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("confused", PassKind::Compute)
        .read(&foreign, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    assert!(matches!(
        compile(&rg).unwrap_err(),
        GraphError::UnknownResource { .. }
    ));
}

fn chain(frame: u64, extent: u32) -> RenderGraph {
    let mut rg = RenderGraph::new(frame);
    let mut a = rg.create_image(
        "a",
        ImageDesc::new_2d(vk::Format::R8G8B8A8_UNORM, extent, extent),
    );
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("make", PassKind::Compute)
        .write(&mut a, ImageAccess::StorageWriteCompute);
    rg.pass("use", PassKind::Compute)
        .read(&a, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg
}

#[test]
fn compilation_is_cached_while_the_shape_is_unchanged() {
    let mut compiler = Compiler::new();
    let first = compiler.compile(&chain(0, 64), &FakeMemory).unwrap();
    let second = compiler.compile(&chain(1, 64), &FakeMemory).unwrap();
    assert_eq!(compiler.compilations(), 1);
    assert!(std::sync::Arc::ptr_eq(&first, &second));
    compiler.compile(&chain(2, 32), &FakeMemory).unwrap();
    assert_eq!(compiler.compilations(), 2);
}

#[test]
fn the_dumps_describe_order_barriers_and_memory() {
    let plan = compile(&chain(0, 64)).unwrap();
    let dump = plan.dump();
    assert!(dump.dot.starts_with("digraph plan {"));
    assert!(dump.dot.contains("0: make"));
    assert!(dump.dot.contains("1: use"));
    assert!(dump.dot.contains("GENERAL -> SHADER_READ_ONLY_OPTIMAL"));
    let json: serde_json::Value = serde_json::from_str(&dump.json).unwrap();
    assert_eq!(json["passes"][0]["name"], "make");
    assert_eq!(json["passes"][1]["name"], "use");
    let b = &json["passes"][1]["barriers"][0];
    assert_eq!(b["resource_name"], "a");
    assert_eq!(b["src_stage"], "COMPUTE_SHADER");
    assert_eq!(b["dst_access"], "SHADER_SAMPLED_READ");
    assert_eq!(b["old_layout"], "GENERAL");
    let first = &json["passes"][0]["barriers"][0];
    assert_eq!(first["src_stage"], "NONE");
    assert_eq!(first["old_layout"], "UNDEFINED");
    assert_eq!(b["new_layout"], "SHADER_READ_ONLY_OPTIMAL");
    assert_eq!(json["memory"]["requested_bytes"], 64 * 64 * 4);
    assert_eq!(json["resources"][0]["kind"], "transient");
}
