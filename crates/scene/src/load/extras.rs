//! What shine reads from glTF `extras`: the environment in the root's
//! ([`environment::EXTRAS_KEY`]) and explicit proxy spheres in a node's
//! ([`proxies::EXTRAS_KEY`]); animated nodes without explicit proxies get fitted ones.

use std::path::Path;

use super::ctx::Ctx;
use super::uri;
use crate::environment::{self, Environment};
use crate::error::Result;
use crate::proxies::{self, NodeProxies, ProxySource, ProxySphere};
use crate::scene::Scene;

/// The environment described in the root `extras`, `None` when there is none; URIs in it
/// resolve against `base_dir`.
pub(super) fn load_environment(
    ctx: &Ctx,
    doc: &gltf::Document,
    base_dir: Option<&Path>,
) -> Result<Option<Environment>> {
    let Some(raw) = &doc.as_json().extras else {
        return Ok(None);
    };
    let v: serde_json::Value = serde_json::from_str(raw.get())
        .map_err(|e| ctx.invalid("extras", format!("not JSON: {e}")))?;
    let Some(env) = v.get(environment::EXTRAS_KEY) else {
        return Ok(None);
    };
    let fetch = |uri: &str| uri::fetch(uri, base_dir);
    Environment::from_json(env, &fetch)
        .map(Some)
        .map_err(|m| ctx.invalid(format!("extras.{}", environment::EXTRAS_KEY), m))
}

/// Proxy spheres of the shown nodes of `scene`: explicit ones from a node's `extras`, else
/// [`proxies::DEFAULT_PROXY_COUNT`] spheres fitted to the mesh of an animated node.
pub(super) fn load_proxies(
    ctx: &Ctx,
    doc: &gltf::Document,
    scene: &Scene,
) -> Result<Vec<NodeProxies>> {
    let mut out = Vec::new();
    let shown = scene.shown_nodes();
    for node in doc.nodes() {
        let i = node.index();
        if !shown.get(i).copied().unwrap_or(false) {
            continue;
        }
        if let Some(spheres) = explicit_proxies(ctx, &node)? {
            out.push(NodeProxies {
                node: i,
                spheres,
                source: ProxySource::Explicit,
            });
            continue;
        }
        let Some(mesh) = node.mesh().and_then(|m| scene.meshes.get(m.index())) else {
            continue;
        };
        if scene.is_animated(i) {
            let fit = proxies::fit(mesh, proxies::DEFAULT_PROXY_COUNT);
            out.push(NodeProxies {
                node: i,
                spheres: fit.spheres,
                source: ProxySource::Fitted(fit.error),
            });
        }
    }
    Ok(out)
}

/// The spheres listed under [`proxies::EXTRAS_KEY`] in the node's `extras`, `None` when
/// there are none.
fn explicit_proxies(ctx: &Ctx, node: &gltf::Node<'_>) -> Result<Option<Vec<ProxySphere>>> {
    let Some(raw) = node.extras() else {
        return Ok(None);
    };
    let element = format!(
        "nodes[{}] {:?} extras",
        node.index(),
        node.name().unwrap_or("")
    );
    let v: serde_json::Value = serde_json::from_str(raw.get())
        .map_err(|e| ctx.invalid(&element, format!("not JSON: {e}")))?;
    let Some(p) = v.get(proxies::EXTRAS_KEY) else {
        return Ok(None);
    };
    proxies::from_json(p)
        .map(Some)
        .map_err(|m| ctx.invalid(format!("{element}.{}", proxies::EXTRAS_KEY), m))
}
