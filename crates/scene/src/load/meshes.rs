//! Meshes: their primitives are independent, so they are decoded (normals and tangents
//! generated) on all cores, then gathered with their warnings and the first error in file
//! order.

use super::accessor::Buffers;
use super::ctx::Ctx;
use super::primitive::load_primitive;
use crate::error::Result;
use crate::types::{Material, Mesh, NO_TEXTURE, Primitive};

/// The meshes of the file and whether a primitive uses the glTF default material.
pub(super) struct LoadedMeshes {
    /// One per glTF mesh, in file order; skipped primitives are left out.
    pub(super) meshes: Vec<Mesh>,
    /// Whether a primitive (even a skipped one) has no material and so refers to the
    /// default material at `default_material`.
    pub(super) uses_default_material: bool,
}

/// Loads every mesh of `doc`. Primitives without a material refer to `default_material`;
/// `materials` says which primitives are normal-mapped (and so need MikkTSpace tangents).
pub(super) fn load_meshes(
    ctx: &mut Ctx,
    buffers: &Buffers,
    doc: &gltf::Document,
    materials: &[Material],
    default_material: u32,
) -> Result<LoadedMeshes> {
    let (mut meshes, jobs) = plan(doc, materials, default_material);
    let uses_default_material = jobs.iter().any(|j| j.material == default_material);
    for (job, (result, warnings)) in jobs.iter().zip(load_primitives(ctx.file(), buffers, &jobs)) {
        ctx.warnings.extend(warnings);
        if let (Some(p), Some(mesh)) = (result?, meshes.get_mut(job.mesh)) {
            mesh.primitives.push(p);
        }
    }
    for (mesh, json) in meshes.iter_mut().zip(doc.meshes()) {
        mesh.weights = mesh_weights(ctx, mesh, &json)?;
    }
    Ok(LoadedMeshes {
        meshes,
        uses_default_material,
    })
}

/// The mesh's default morph weights, one per target (zeros when the file gives none),
/// after checking that every primitive has the same number of targets and the file's
/// weights match it and are finite.
fn mesh_weights(ctx: &Ctx, mesh: &Mesh, json: &gltf::Mesh<'_>) -> Result<Vec<f32>> {
    let element = format!("meshes[{}] {:?}", json.index(), mesh.name);
    let targets = mesh.target_count();
    if mesh.primitives.iter().any(|p| p.targets.len() != targets) {
        return Err(ctx.invalid(
            &element,
            "its primitives have different numbers of morph targets; glTF requires the same",
        ));
    }
    let Some(weights) = json.weights() else {
        return Ok(vec![0.0; targets]);
    };
    if weights.len() != targets || weights.iter().any(|w| !w.is_finite()) {
        return Err(ctx.invalid(
            format!("{element} weights"),
            format!(
                "has {} weights for {targets} morph targets, or a NaN or infinite one",
                weights.len()
            ),
        ));
    }
    Ok(weights.to_vec())
}

/// A loaded primitive (or `None`: skipped with a warning) and the warnings met.
type PrimitiveResult = (Result<Option<Primitive>>, Vec<String>);

/// One primitive to load, with what it needs to know about its mesh and material.
struct PrimitiveJob<'d> {
    mesh: usize,
    prim: gltf::Primitive<'d>,
    element: String,
    material: u32,
    normal_mapped: bool,
}

/// The meshes with no primitives yet, and one job per primitive in file order.
fn plan<'d>(
    doc: &'d gltf::Document,
    materials: &[Material],
    default_material: u32,
) -> (Vec<Mesh>, Vec<PrimitiveJob<'d>>) {
    let mut jobs = Vec::new();
    let mut meshes = Vec::new();
    for mesh in doc.meshes() {
        let mesh_name = mesh
            .name()
            .map_or_else(|| format!("mesh{}", mesh.index()), str::to_string);
        for prim in mesh.primitives() {
            let element = format!(
                "meshes[{}] {:?} primitives[{}]",
                mesh.index(),
                mesh_name,
                prim.index()
            );
            let material = prim
                .material()
                .index()
                .map_or(default_material, |i| i as u32);
            let normal_mapped = materials
                .get(material as usize)
                .is_some_and(|m| m.normal_texture != NO_TEXTURE);
            jobs.push(PrimitiveJob {
                mesh: meshes.len(),
                prim,
                element,
                material,
                normal_mapped,
            });
        }
        meshes.push(Mesh {
            name: mesh_name,
            primitives: Vec::new(),
            weights: Vec::new(),
        });
    }
    (meshes, jobs)
}

/// Loads every job, on up to `available_parallelism` threads; results in job order, each
/// with its warnings.
fn load_primitives(
    file: &str,
    buffers: &Buffers,
    jobs: &[PrimitiveJob<'_>],
) -> Vec<PrimitiveResult> {
    let run = |job: &PrimitiveJob<'_>| {
        let mut ctx = Ctx::new(file);
        let result = load_primitive(
            &mut ctx,
            buffers,
            &job.prim,
            &job.element,
            job.material,
            job.normal_mapped,
        );
        (result, ctx.warnings)
    };
    let threads = std::thread::available_parallelism()
        .map_or(1, |n| n.get())
        .min(jobs.len());
    if threads <= 1 {
        return jobs.iter().map(run).collect();
    }
    let done = run_on_threads(jobs, threads, run);
    in_job_order(file, jobs, done)
}

/// Runs `run` over `jobs` on `threads` scoped threads pulling jobs from a shared counter;
/// results tagged with their job index, in no particular order.
fn run_on_threads<'d>(
    jobs: &[PrimitiveJob<'d>],
    threads: usize,
    run: impl Fn(&PrimitiveJob<'d>) -> PrimitiveResult + Sync,
) -> Vec<(usize, PrimitiveResult)> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    let mut out = Vec::new();
                    loop {
                        let i = next.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
                        let Some(job) = jobs.get(i) else { break };
                        out.push((i, run(job)));
                    }
                    out
                })
            })
            .collect();
        // A worker only panics if loading panicked, which the loader must never do; its
        // jobs are then reported as failed rather than lost silently.
        workers
            .into_iter()
            .flat_map(|w| w.join().unwrap_or_default())
            .collect()
    })
}

/// The results of [`run_on_threads`] in job order; a job without a result (its worker
/// panicked) becomes an error naming its primitive.
fn in_job_order(
    file: &str,
    jobs: &[PrimitiveJob<'_>],
    mut done: Vec<(usize, PrimitiveResult)>,
) -> Vec<PrimitiveResult> {
    done.sort_by_key(|(i, _)| *i);
    let mut out: Vec<PrimitiveResult> = Vec::with_capacity(jobs.len());
    let mut results = done.into_iter().peekable();
    for (i, job) in jobs.iter().enumerate() {
        match results.next_if(|(k, _)| *k == i) {
            Some((_, r)) => out.push(r),
            None => out.push((
                Err(Ctx::new(file).invalid(
                    job.element.clone(),
                    "loading this primitive failed unexpectedly",
                )),
                Vec::new(),
            )),
        }
    }
    out
}
