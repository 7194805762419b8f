//! Exact barriers and layouts for the classic hazards, on fixture graphs (no GPU).

mod common;

use common::*;
use shine_graph::vk::{AccessFlags2 as A, ImageLayout as L, PipelineStageFlags2 as S};
use shine_graph::*;

const NO_LAYOUT: (L, L) = (L::UNDEFINED, L::UNDEFINED);

#[test]
fn read_after_write_transitions_storage_to_sampled() {
    let mut rg = RenderGraph::new(0);
    let mut a = rg.create_image("a", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("write", PassKind::Compute)
        .write(&mut a, ImageAccess::StorageWriteCompute);
    rg.pass("read", PassKind::Compute)
        .read(&a, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["write", "read"]);
    assert_eq!(
        plan.barriers_before("write"),
        [barrier(
            a.id(),
            (S::NONE, A::NONE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (L::UNDEFINED, L::GENERAL),
        )]
    );
    assert_eq!(
        plan.barriers_before("read"),
        [barrier(
            a.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            (L::GENERAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
    assert!(plan.final_barriers.is_empty());
}

#[test]
fn write_after_read_waits_for_the_reader_without_memory_dependency() {
    let mut rg = RenderGraph::new(0);
    let mut buf = rg.create_buffer("buf", BufferDesc::new(1024));
    let mut out = output_buffer(&mut rg, "out");
    let mut out2 = output_buffer(&mut rg, "out2");
    rg.pass("fill", PassKind::Transfer)
        .write(&mut buf, BufferAccess::Fill);
    rg.pass("read", PassKind::Compute)
        .read(&buf, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("overwrite", PassKind::Compute)
        .write(&mut buf, BufferAccess::StorageWriteCompute);
    rg.pass("copy", PassKind::Transfer)
        .read(&buf, BufferAccess::CopySrc)
        .write(&mut out2, BufferAccess::CopyDst);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["fill", "read", "overwrite", "copy"]);
    assert_eq!(plan.barriers_before("fill"), []);
    assert_eq!(
        plan.barriers_before("read"),
        [barrier(
            buf.id(),
            (S::CLEAR | S::COPY, A::TRANSFER_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ),
            NO_LAYOUT,
        )]
    );
    assert_eq!(
        plan.barriers_before("overwrite"),
        [barrier(
            buf.id(),
            (S::COMPUTE_SHADER, A::NONE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            NO_LAYOUT,
        )]
    );
    assert_eq!(
        plan.barriers_before("copy"),
        [barrier(
            buf.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COPY, A::TRANSFER_READ),
            NO_LAYOUT,
        )]
    );
}

#[test]
fn write_after_write_orders_both_writes() {
    let mut rg = RenderGraph::new(0);
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("first", PassKind::Compute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("second", PassKind::Transfer)
        .write(&mut out, BufferAccess::CopyDst);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.order(), ["first", "second"]);
    assert_eq!(plan.barriers_before("first"), []);
    assert_eq!(
        plan.barriers_before("second"),
        [barrier(
            out.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COPY, A::TRANSFER_WRITE),
            NO_LAYOUT,
        )]
    );
}

#[test]
fn read_after_read_needs_no_second_barrier() {
    let mut rg = RenderGraph::new(0);
    let mut buf = rg.create_buffer("buf", BufferDesc::new(1024));
    let mut out = output_buffer(&mut rg, "out");
    let mut out2 = output_buffer(&mut rg, "out2");
    rg.pass("write", PassKind::Compute)
        .write(&mut buf, BufferAccess::StorageWriteCompute);
    rg.pass("read1", PassKind::Compute)
        .read(&buf, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("read2", PassKind::Compute)
        .read(&buf, BufferAccess::StorageReadCompute)
        .write(&mut out2, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(
        plan.barriers_before("read1"),
        [barrier(
            buf.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_READ),
            NO_LAYOUT,
        )]
    );
    assert_eq!(plan.barriers_before("read2"), []);
}

#[test]
fn attachment_then_sampled_in_fragment_then_compute() {
    let mut rg = RenderGraph::new(0);
    let mut color = rg.create_image("color", image());
    let mut out = output_buffer(&mut rg, "out");
    let mut out2 = output_buffer(&mut rg, "out2");
    rg.pass("draw", PassKind::Raster)
        .write(&mut color, ImageAccess::ColorAttachmentWrite);
    rg.pass("sample_fs", PassKind::Raster)
        .read(&color, ImageAccess::SampledFragment)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    rg.pass("sample_cs", PassKind::Compute)
        .read(&color, ImageAccess::SampledCompute)
        .write(&mut out2, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(
        plan.barriers_before("draw"),
        [barrier(
            color.id(),
            (S::NONE, A::NONE),
            (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
            (L::UNDEFINED, L::COLOR_ATTACHMENT_OPTIMAL),
        )]
    );
    assert_eq!(
        plan.barriers_before("sample_fs"),
        [barrier(
            color.id(),
            (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
            (S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ),
            (L::COLOR_ATTACHMENT_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
    // Same layout, new stage: waits for the attachment write and chains through the
    // transition (whose second scope was the fragment stage).
    assert_eq!(
        plan.barriers_before("sample_cs"),
        [barrier(
            color.id(),
            (
                S::COLOR_ATTACHMENT_OUTPUT | S::FRAGMENT_SHADER,
                A::COLOR_ATTACHMENT_WRITE
            ),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            (L::SHADER_READ_ONLY_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
}

#[test]
fn depth_attachment_then_sampled_in_compute() {
    let mut rg = RenderGraph::new(0);
    let mut depth = rg.create_image("depth", ImageDesc::new_2d(vk::Format::D32_SFLOAT, 64, 64));
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("depth_prepass", PassKind::Raster)
        .write(&mut depth, ImageAccess::DepthAttachmentWrite);
    rg.pass("ssao", PassKind::Compute)
        .read(&depth, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    let tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    let rw = A::DEPTH_STENCIL_ATTACHMENT_READ | A::DEPTH_STENCIL_ATTACHMENT_WRITE;
    assert_eq!(
        plan.barriers_before("depth_prepass"),
        [barrier(
            depth.id(),
            (S::NONE, A::NONE),
            (tests, rw),
            (L::UNDEFINED, L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
        )]
    );
    assert_eq!(
        plan.barriers_before("ssao"),
        [barrier(
            depth.id(),
            (tests, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            (
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                L::SHADER_READ_ONLY_OPTIMAL
            ),
        )]
    );
}

#[test]
fn compute_write_then_vertex_read_and_final_layout() {
    let mut rg = RenderGraph::new(0);
    let mut verts = rg.create_buffer("verts", BufferDesc::new(4096));
    let mut target = rg.import_image(
        "target",
        image(),
        ImageImport {
            initial: ExternalState::UNDEFINED,
            final_state: ExternalState::new(
                S::FRAGMENT_SHADER,
                A::SHADER_SAMPLED_READ,
                L::SHADER_READ_ONLY_OPTIMAL,
            ),
            usage: vk::ImageUsageFlags::COLOR_ATTACHMENT | vk::ImageUsageFlags::SAMPLED,
            read_only: false,
        },
    );
    rg.pass("generate", PassKind::Compute)
        .write(&mut verts, BufferAccess::StorageWriteCompute);
    rg.pass("draw", PassKind::Raster)
        .read(&verts, BufferAccess::Vertex)
        .write(&mut target, ImageAccess::ColorAttachmentReadWrite);
    let plan = compile(&rg).unwrap();
    assert_eq!(plan.barriers_before("generate"), []);
    let color_rw = A::COLOR_ATTACHMENT_READ | A::COLOR_ATTACHMENT_WRITE;
    assert_eq!(
        plan.barriers_before("draw"),
        [
            barrier(
                verts.id(),
                (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
                (S::VERTEX_ATTRIBUTE_INPUT, A::VERTEX_ATTRIBUTE_READ),
                NO_LAYOUT,
            ),
            barrier(
                target.id(),
                (S::NONE, A::NONE),
                (S::COLOR_ATTACHMENT_OUTPUT, color_rw),
                (L::UNDEFINED, L::COLOR_ATTACHMENT_OPTIMAL),
            ),
        ]
    );
    assert_eq!(
        plan.final_barriers,
        [barrier(
            target.id(),
            (S::COLOR_ATTACHMENT_OUTPUT, A::COLOR_ATTACHMENT_WRITE),
            (S::FRAGMENT_SHADER, A::SHADER_SAMPLED_READ),
            (L::COLOR_ATTACHMENT_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
    let usage = |id| plan.resource(id).unwrap().usage;
    assert_eq!(
        usage(verts.id()),
        Usage::Buffer(vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::VERTEX_BUFFER)
    );
}

#[test]
fn imported_image_waits_for_the_callers_write() {
    let mut rg = RenderGraph::new(0);
    let input = rg.import_image(
        "input",
        image(),
        ImageImport {
            initial: ExternalState::new(S::COPY, A::TRANSFER_WRITE, L::TRANSFER_DST_OPTIMAL),
            final_state: ExternalState::UNDEFINED,
            usage: vk::ImageUsageFlags::SAMPLED | vk::ImageUsageFlags::TRANSFER_DST,
            read_only: true,
        },
    );
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("use", PassKind::Compute)
        .read(&input, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(
        plan.barriers_before("use"),
        [barrier(
            input.id(),
            (S::COPY, A::TRANSFER_WRITE),
            (S::COMPUTE_SHADER, A::SHADER_SAMPLED_READ),
            (L::TRANSFER_DST_OPTIMAL, L::SHADER_READ_ONLY_OPTIMAL),
        )]
    );
    assert!(plan.final_barriers.is_empty());
}

#[test]
fn usage_flags_are_the_union_of_accesses() {
    let mut rg = RenderGraph::new(0);
    let mut img = rg.create_image("img", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("clear", PassKind::Transfer)
        .write(&mut img, ImageAccess::ClearDst);
    rg.pass("draw", PassKind::Raster)
        .write(&mut img, ImageAccess::ColorAttachmentReadWrite);
    rg.pass("use", PassKind::Compute)
        .read(&img, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    use vk::ImageUsageFlags as U;
    assert_eq!(
        plan.resource(img.id()).unwrap().usage,
        Usage::Image(U::TRANSFER_DST | U::COLOR_ATTACHMENT | U::SAMPLED)
    );
}

#[test]
fn two_accesses_of_one_pass_merge_into_one_barrier() {
    let mut rg = RenderGraph::new(0);
    let mut buf = rg.create_buffer("args", BufferDesc::new(64));
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("build", PassKind::Compute)
        .write(&mut buf, BufferAccess::StorageWriteCompute);
    rg.pass("consume", PassKind::Compute)
        .read(&buf, BufferAccess::Indirect)
        .read(&buf, BufferAccess::StorageReadCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    assert_eq!(
        plan.barriers_before("consume"),
        [barrier(
            buf.id(),
            (S::COMPUTE_SHADER, A::SHADER_STORAGE_WRITE),
            (
                S::DRAW_INDIRECT | S::COMPUTE_SHADER,
                A::INDIRECT_COMMAND_READ | A::SHADER_STORAGE_READ
            ),
            NO_LAYOUT,
        )]
    );
}

#[test]
fn a_tested_depth_attachment_can_be_sampled_in_the_same_pass() {
    let mut rg = RenderGraph::new(0);
    let mut depth = rg.create_image("depth", ImageDesc::new_2d(vk::Format::D32_SFLOAT, 64, 64));
    let mut color = rg.create_image("color", image());
    let mut out = output_buffer(&mut rg, "out");
    rg.pass("prepass", PassKind::Raster)
        .write(&mut depth, ImageAccess::DepthAttachmentWrite);
    rg.pass("decals", PassKind::Raster)
        .read(&depth, ImageAccess::DepthAttachmentRead)
        .read(&depth, ImageAccess::SampledFragment)
        .write(&mut color, ImageAccess::ColorAttachmentWrite);
    rg.pass("resolve", PassKind::Compute)
        .read(&color, ImageAccess::SampledCompute)
        .write(&mut out, BufferAccess::StorageWriteCompute);
    let plan = compile(&rg).unwrap();
    // Both reads share DEPTH_STENCIL_READ_ONLY_OPTIMAL, reached in one barrier.
    let tests = S::EARLY_FRAGMENT_TESTS | S::LATE_FRAGMENT_TESTS;
    assert_eq!(
        plan.barriers_before("decals")[0],
        barrier(
            depth.id(),
            (tests, A::DEPTH_STENCIL_ATTACHMENT_WRITE),
            (
                tests | S::FRAGMENT_SHADER,
                A::DEPTH_STENCIL_ATTACHMENT_READ | A::SHADER_SAMPLED_READ
            ),
            (
                L::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                L::DEPTH_STENCIL_READ_ONLY_OPTIMAL
            ),
        )
    );
    use vk::ImageUsageFlags as U;
    assert_eq!(
        plan.resource(depth.id()).unwrap().usage,
        Usage::Image(U::DEPTH_STENCIL_ATTACHMENT | U::SAMPLED)
    );
}
