//! Reflection of a naga module: the descriptor bindings, push-constant size and vertex inputs
//! of a shader, as `shader_build` writes them into `$OUT_DIR/shaders.rs`.

use super::{Binding, DescriptorKind, VertexInput};

pub(super) fn reflect_globals(module: &naga::Module) -> Result<(Vec<Binding>, u32), String> {
    let mut bindings = Vec::new();
    let mut push_constant_size = 0;
    for (_, var) in module.global_variables.iter() {
        let ty = &module.types[var.ty];
        if var.space == naga::AddressSpace::Immediate {
            push_constant_size = ty.inner.size(module.to_ctx());
            continue;
        }
        let Some(rb) = &var.binding else { continue };
        let (inner, count) = match &ty.inner {
            naga::TypeInner::BindingArray { base, size } => {
                let count = match size {
                    naga::ArraySize::Constant(n) => n.get(),
                    _ => return Err("unsized descriptor arrays need descriptor indexing".into()),
                };
                (&module.types[*base].inner, count)
            }
            other => (other, 1),
        };
        let kind = match (var.space, inner) {
            (naga::AddressSpace::Uniform, _) => DescriptorKind::UniformBuffer,
            (naga::AddressSpace::Storage { access }, _) => DescriptorKind::StorageBuffer {
                writable: access.contains(naga::StorageAccess::STORE),
            },
            (naga::AddressSpace::Handle, naga::TypeInner::Sampler { .. }) => {
                DescriptorKind::Sampler
            }
            (naga::AddressSpace::Handle, naga::TypeInner::Image { class, .. }) => match class {
                naga::ImageClass::Storage { access, .. } => DescriptorKind::StorageImage {
                    writable: access.contains(naga::StorageAccess::STORE),
                },
                _ => DescriptorKind::SampledImage,
            },
            (space, inner) => {
                return Err(format!("unsupported resource {space:?} of type {inner:?}"));
            }
        };
        let name = var
            .name
            .clone()
            .filter(|n| !n.is_empty())
            .or_else(|| ty.name.clone())
            .unwrap_or_else(|| format!("binding{}_{}", rb.group, rb.binding));
        bindings.push(Binding {
            set: rb.group,
            binding: rb.binding,
            name,
            kind,
            count,
        });
    }
    bindings.sort_by_key(|b| (b.set, b.binding));
    Ok((bindings, push_constant_size))
}

pub(super) fn reflect_vertex_inputs(
    module: &naga::Module,
    entry: &naga::EntryPoint,
) -> Result<Vec<VertexInput>, String> {
    let mut inputs = Vec::new();
    let mut add = |binding: &Option<naga::Binding>, ty: naga::Handle<naga::Type>| {
        if let Some(naga::Binding::Location { location, .. }) = binding {
            let format = vertex_format(&module.types[ty].inner).ok_or_else(|| {
                format!("vertex input at location {location} has no vertex format")
            })?;
            inputs.push(VertexInput {
                location: *location,
                format,
            });
        }
        Ok::<(), String>(())
    };
    for arg in &entry.function.arguments {
        if let naga::TypeInner::Struct { members, .. } = &module.types[arg.ty].inner {
            for member in members {
                add(&member.binding, member.ty)?;
            }
        } else {
            add(&arg.binding, arg.ty)?;
        }
    }
    inputs.sort_by_key(|i| i.location);
    Ok(inputs)
}

fn vertex_format(inner: &naga::TypeInner) -> Option<&'static str> {
    let (kind, width, size) = match *inner {
        naga::TypeInner::Scalar(s) => (s.kind, s.width, 1),
        naga::TypeInner::Vector { size, scalar } => (scalar.kind, scalar.width, size as u8),
        _ => return None,
    };
    if width != 4 {
        return None;
    }
    use naga::ScalarKind::{Float, Sint, Uint};
    Some(match (kind, size) {
        (Float, 1) => "R32_SFLOAT",
        (Float, 2) => "R32G32_SFLOAT",
        (Float, 3) => "R32G32B32_SFLOAT",
        (Float, 4) => "R32G32B32A32_SFLOAT",
        (Sint, 1) => "R32_SINT",
        (Sint, 2) => "R32G32_SINT",
        (Sint, 3) => "R32G32B32_SINT",
        (Sint, 4) => "R32G32B32A32_SINT",
        (Uint, 1) => "R32_UINT",
        (Uint, 2) => "R32G32_UINT",
        (Uint, 3) => "R32G32B32_UINT",
        (Uint, 4) => "R32G32B32A32_UINT",
        _ => return None,
    })
}
