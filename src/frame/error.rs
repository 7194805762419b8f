//! [`RenderError`]: everything a frame can refuse or fail at, one variant per layer.

use crate::capture::image_io::ImageIoError;
use crate::gpu_scene::SceneUploadError;
use crate::passes::aaf::AafError;
use crate::passes::amortise::AmortiseError;
use crate::passes::brdf_tables::BrdfTablesError;
use crate::passes::environment_sh::EnvironmentShError;
use crate::passes::gi_add::GiAddError;
use crate::passes::hvl::HvlError;
use crate::passes::igi::IgiError;
use crate::passes::proxy::ProxyError;
use crate::passes::receivers::ReceiverError;
use crate::passes::shadows::ShadowLayoutError;
use crate::settings::SettingsError;
use shine_graph::ExecuteError;

/// What can go wrong while rendering.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// A device-layer failure.
    #[error(transparent)]
    Gpu(#[from] shine_gpu::Error),
    /// The frame graph could not be compiled or recorded.
    #[error("frame graph: {0}")]
    Graph(#[from] ExecuteError),
    /// The scene could not be uploaded.
    #[error(transparent)]
    Scene(#[from] SceneUploadError),
    /// The settings are invalid.
    #[error(transparent)]
    Settings(#[from] SettingsError),
    /// A read-back frame did not match its expected size.
    #[error(transparent)]
    Image(#[from] ImageIoError),
    /// The HVL passes refused their inputs or parameters.
    #[error(transparent)]
    Hvl(#[from] HvlError),
    /// The IGI passes refused their inputs or parameters.
    #[error(transparent)]
    Igi(#[from] IgiError),
    /// The proxy passes refused their inputs or parameters.
    #[error(transparent)]
    Proxy(#[from] ProxyError),
    /// The AAF passes refused their parameters.
    #[error(transparent)]
    Aaf(#[from] AafError),
    /// An amortised technique's resolve refused its slice.
    #[error(transparent)]
    Amortise(#[from] AmortiseError),
    /// The sky pass refused its parameters.
    #[error(transparent)]
    Sky(#[from] crate::passes::sky::SkyError),
    /// The specular pass refused its parameters.
    #[error(transparent)]
    Specular(#[from] crate::passes::specular::SpecularError),
    /// The denoiser refused its parameters.
    #[error(transparent)]
    Denoise(#[from] crate::passes::denoise::DenoiseError),
    /// A host's environment map could not be projected.
    #[error(transparent)]
    EnvironmentSh(#[from] EnvironmentShError),
    /// The BRDF SH tables could not be built or uploaded.
    #[error(transparent)]
    BrdfTables(#[from] BrdfTablesError),
    /// Two indirect terms of different sizes were summed.
    #[error(transparent)]
    GiAdd(#[from] GiAddError),
    /// The receiver or upsample pass refused its inputs.
    #[error(transparent)]
    Receivers(#[from] ReceiverError),
    /// The scene's lights do not fit one shadow atlas.
    #[error(transparent)]
    Shadows(#[from] ShadowLayoutError),
    /// `render` was called before `set_scene`.
    #[error("no scene: call set_scene first")]
    NoScene,
    /// A parameter is out of range.
    #[error("{0}")]
    Invalid(String),
}
