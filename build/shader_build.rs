//! Build-time shader pipeline: GLSL → glslang (Vulkan 1.3, SPIR-V 1.5) → naga (parse, validate,
//! reflect) → Rust source describing every shader.
//!
//! This file is shared by `build.rs` and by the `shader_build` integration test (through
//! `#[path]`), so the errors a developer sees at build time are the ones the test checks.
//! It knows nothing of shine-gpu: it writes source text that names `shine_gpu` types.

#[path = "shader_codegen.rs"]
pub mod codegen;
#[path = "shader_reflect.rs"]
mod reflect;

use codegen::identifier;
use reflect::{reflect_globals, reflect_vertex_inputs};
use std::collections::BTreeSet;
use std::fmt;
use std::path::{Path, PathBuf};

/// Shader stages recognised by file extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// `.comp`
    Compute,
    /// `.vert`
    Vertex,
    /// `.frag`
    Fragment,
}

impl Stage {
    fn from_extension(ext: &str) -> Option<Self> {
        match ext {
            "comp" => Some(Self::Compute),
            "vert" => Some(Self::Vertex),
            "frag" => Some(Self::Fragment),
            _ => None,
        }
    }

    fn glslang(self) -> glslang::ShaderStage {
        match self {
            Self::Compute => glslang::ShaderStage::Compute,
            Self::Vertex => glslang::ShaderStage::Vertex,
            Self::Fragment => glslang::ShaderStage::Fragment,
        }
    }

    fn rust(self) -> &'static str {
        match self {
            Self::Compute => "Compute",
            Self::Vertex => "Vertex",
            Self::Fragment => "Fragment",
        }
    }
}

/// Descriptor kinds the engine binds; mirrors `shine_gpu::DescriptorKind`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DescriptorKind {
    /// `uniform` block.
    UniformBuffer,
    /// `buffer` block; `writable` is false for `readonly` blocks.
    StorageBuffer {
        /// Whether the shader may write it.
        writable: bool,
    },
    /// `texture2D` and friends (separate from the sampler).
    SampledImage,
    /// `image2D` and friends.
    StorageImage {
        /// Whether the shader may write it.
        writable: bool,
    },
    /// `sampler` / `samplerShadow`.
    Sampler,
}

/// One reflected descriptor binding.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Binding {
    /// Descriptor set index.
    pub set: u32,
    /// Binding index inside the set.
    pub binding: u32,
    /// Variable name (or block type name for anonymous blocks).
    pub name: String,
    /// What kind of descriptor.
    pub kind: DescriptorKind,
    /// Array length (1 for a non-array).
    pub count: u32,
}

/// One reflected vertex input.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct VertexInput {
    /// `layout(location = N)`.
    pub location: u32,
    /// Vulkan format name as in `ash::vk::Format` (`R32G32B32_SFLOAT`).
    pub format: &'static str,
}

/// A compiled, validated and reflected shader module.
#[derive(Clone, Debug)]
pub struct CompiledShader {
    /// Name used at run time: path under shaders/ plus `:variant` when there is one.
    pub name: String,
    /// Rust identifier of the generated static.
    pub ident: String,
    /// Pipeline stage.
    pub stage: Stage,
    /// SPIR-V words.
    pub spirv: Vec<u32>,
    /// Descriptor bindings sorted by (set, binding).
    pub bindings: Vec<Binding>,
    /// Size in bytes of the push-constant block (0 when none).
    pub push_constant_size: u32,
    /// `local_size` of a compute shader, `[0; 3]` otherwise.
    pub workgroup_size: [u32; 3],
    /// Vertex inputs of a vertex shader, sorted by location.
    pub vertex_inputs: Vec<VertexInput>,
    /// Defines the variant was compiled with.
    pub defines: Vec<(String, String)>,
}

/// Why a shader did not build. `Display` always names the file, and the line where known.
#[derive(Debug)]
pub struct ShaderError {
    /// File the error is in (may be an include).
    pub file: PathBuf,
    /// 1-based line, when the error can be placed.
    pub line: Option<u32>,
    /// What went wrong.
    pub message: String,
}

impl fmt::Display for ShaderError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(line) => write!(f, "{}:{}: {}", self.file.display(), line, self.message),
            None => write!(f, "{}: {}", self.file.display(), self.message),
        }
    }
}

/// Everything the build produced: the shaders and every file they read.
pub struct Output {
    /// Compiled shaders, in file order.
    pub shaders: Vec<CompiledShader>,
    /// Every source and include that was read (for `rerun-if-changed`).
    pub inputs: BTreeSet<PathBuf>,
}

/// Constructs naga's SPIR-V reader rejects (ANCHORS.md), found in the GLSL source so the error
/// can name the line instead of a SPIR-V instruction.
const UNREADABLE_BY_NAGA: &[(&str, &str)] = &[
    (
        "sampler1D",
        "combined image samplers: use a separate texture + sampler",
    ),
    (
        "sampler2D",
        "combined image samplers: use a separate texture + sampler",
    ),
    (
        "sampler3D",
        "combined image samplers: use a separate texture + sampler",
    ),
    (
        "samplerCube",
        "combined image samplers: use a separate texture + sampler",
    ),
    ("subgroup", "subgroup operations"),
    ("GL_KHR_shader_subgroup", "subgroup operations"),
    ("imageAtomic", "image atomics"),
    ("buffer_reference", "buffer device address"),
    ("local_size_x_id", "spec-constant workgroup sizes"),
    ("local_size_y_id", "spec-constant workgroup sizes"),
    ("local_size_z_id", "spec-constant workgroup sizes"),
];

/// Compiles every `.comp`, `.vert` and `.frag` below `root` (except `root/include/`).
pub fn build_all(root: &Path) -> Result<Output, ShaderError> {
    let include_dir = root.join("include");
    let mut sources = Vec::new();
    collect_sources(root, &include_dir, &mut sources)?;
    sources.sort();

    let mut inputs: BTreeSet<PathBuf> = sources.iter().cloned().collect();
    let mut shaders = Vec::new();
    for path in &sources {
        let text = std::fs::read_to_string(path).map_err(|e| ShaderError {
            file: path.clone(),
            line: None,
            message: format!("cannot read: {e}"),
        })?;
        let relative = path
            .strip_prefix(root)
            .unwrap_or(path)
            .to_string_lossy()
            .replace('\\', "/");
        for variant in variants(path, &text)? {
            let mut includes = Includes::new(&include_dir);
            let shader = compile_one(path, &relative, &text, &variant, &mut includes)?;
            inputs.extend(includes.read);
            if let Some(other) = shaders
                .iter()
                .find(|s: &&CompiledShader| s.ident == shader.ident)
            {
                return Err(ShaderError {
                    file: path.clone(),
                    line: None,
                    message: format!(
                        "`{}` and `{}` both become `shaders::{}`: rename one",
                        shader.name, other.name, shader.ident
                    ),
                });
            }
            shaders.push(shader);
        }
    }
    Ok(Output { shaders, inputs })
}

fn collect_sources(dir: &Path, skip: &Path, out: &mut Vec<PathBuf>) -> Result<(), ShaderError> {
    let entries = std::fs::read_dir(dir).map_err(|e| ShaderError {
        file: dir.to_path_buf(),
        line: None,
        message: format!("cannot list shader folder: {e}"),
    })?;
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            if path != skip {
                collect_sources(&path, skip, out)?;
            }
        } else if path
            .extension()
            .and_then(|e| e.to_str())
            .and_then(Stage::from_extension)
            .is_some()
        {
            out.push(path);
        }
    }
    Ok(())
}

/// A `#define` set a shader is compiled with, declared in the shader as
/// `//! variant NAME KEY=VALUE KEY2=VALUE`. A shader without such lines is compiled once.
struct Variant {
    name: Option<String>,
    defines: Vec<(String, String)>,
}

fn variants(path: &Path, text: &str) -> Result<Vec<Variant>, ShaderError> {
    let mut out = Vec::new();
    for (index, line) in text.lines().enumerate() {
        let Some(rest) = line.trim().strip_prefix("//! variant") else {
            continue;
        };
        let error = |message: String| ShaderError {
            file: path.to_path_buf(),
            line: Some(index as u32 + 1),
            message,
        };
        let mut words = rest.split_whitespace();
        let name = words
            .next()
            .filter(|n| n.chars().all(|c| c.is_ascii_alphanumeric() || c == '_'))
            .ok_or_else(|| error("`//! variant` needs a name made of [A-Za-z0-9_]".into()))?;
        let defines = words
            .map(|w| {
                w.split_once('=')
                    .map(|(k, v)| (k.to_string(), v.to_string()))
                    .ok_or_else(|| error(format!("variant define `{w}` is not KEY=VALUE")))
            })
            .collect::<Result<Vec<_>, _>>()?;
        out.push(Variant {
            name: Some(name.to_string()),
            defines,
        });
    }
    if out.is_empty() {
        out.push(Variant {
            name: None,
            defines: Vec::new(),
        });
    }
    Ok(out)
}

/// Resolves `#include "x.glsl"` against shaders/include/, remembers what it read and checks
/// each include for constructs naga cannot read.
struct Includes {
    dir: PathBuf,
    read: Vec<PathBuf>,
    unreadable: Option<ShaderError>,
}

impl Includes {
    fn new(dir: &Path) -> Self {
        Self {
            dir: dir.to_path_buf(),
            read: Vec::new(),
            unreadable: None,
        }
    }
}

impl glslang::include::IncludeHandler for Includes {
    fn include(
        &mut self,
        _ty: glslang::include::IncludeType,
        header_name: &str,
        _includer_name: &str,
        _include_depth: usize,
    ) -> Option<glslang::include::IncludeResult> {
        let path = self.dir.join(header_name);
        let data = std::fs::read_to_string(&path).ok()?;
        if self.unreadable.is_none() {
            self.unreadable = check_naga_subset(&path, &data).err();
        }
        self.read.push(path);
        Some(glslang::include::IncludeResult {
            name: header_name.to_string(),
            data,
        })
    }
}

fn compile_one(
    path: &Path,
    relative: &str,
    text: &str,
    variant: &Variant,
    includes: &mut Includes,
) -> Result<CompiledShader, ShaderError> {
    let stage = path
        .extension()
        .and_then(|e| e.to_str())
        .and_then(Stage::from_extension)
        .ok_or_else(|| ShaderError {
            file: path.to_path_buf(),
            line: None,
            message: "unknown shader stage".into(),
        })?;
    check_naga_subset(path, text)?;

    let error = |line: Option<u32>, message: String| ShaderError {
        file: path.to_path_buf(),
        line,
        message,
    };
    let includes_dir = includes.dir.clone();
    let compiler = glslang::Compiler::acquire()
        .ok_or_else(|| error(None, "glslang could not be initialised".into()))?;
    let source = glslang::ShaderSource::from(text.to_string());
    let options = glslang::CompilerOptions {
        source_language: glslang::SourceLanguage::GLSL,
        target: glslang::Target::Vulkan {
            version: glslang::VulkanVersion::Vulkan1_3,
            spirv_version: glslang::SpirvVersion::SPIRV1_5,
        },
        version_profile: None,
        messages: glslang::ShaderMessage::DEFAULT,
    };
    let defines: Vec<(&str, Option<&str>)> = variant
        .defines
        .iter()
        .map(|(k, v)| (k.as_str(), Some(v.as_str())))
        .collect();
    let input = glslang::ShaderInput::new(
        &source,
        stage.glslang(),
        &options,
        Some(&defines),
        Some(includes),
    )
    .map_err(|e| error(None, format!("glslang rejected the input: {e}")))?;
    let compiled = compiler
        .create_shader(input)
        .and_then(|shader| shader.compile());
    if let Some(unreadable) = includes.unreadable.take() {
        return Err(unreadable);
    }
    let spirv = compiled.map_err(|e| glslang_error(path, &includes_dir, &e))?;

    let module = naga::front::spv::parse_u8_slice(
        bytemuck_words(&spirv).as_slice(),
        &naga::front::spv::Options {
            adjust_coordinate_space: false,
            strict_capabilities: true,
            block_ctx_dump_prefix: None,
        },
    )
    .map_err(|e| {
        error(
            None,
            format!("naga cannot read the SPIR-V: {e} (see shaders/README.md)"),
        )
    })?;
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::all(),
    )
    .validate(&module)
    .map_err(|e| {
        let message = error_chain(e.as_inner());
        error(
            declaration_line(text, &message),
            format!("naga validation failed: {message}"),
        )
    })?;

    let entry = module
        .entry_points
        .first()
        .ok_or_else(|| error(None, "no entry point".into()))?;
    let (bindings, push_constant_size) = reflect_globals(&module).map_err(|m| error(None, m))?;
    let vertex_inputs = if stage == Stage::Vertex {
        reflect_vertex_inputs(&module, entry).map_err(|m| error(None, m))?
    } else {
        Vec::new()
    };
    let workgroup_size = if stage == Stage::Compute {
        entry.workgroup_size
    } else {
        [0; 3]
    };

    let name = match &variant.name {
        Some(v) => format!("{relative}:{v}"),
        None => relative.to_string(),
    };
    Ok(CompiledShader {
        ident: identifier(&name),
        name,
        stage,
        spirv,
        bindings,
        push_constant_size,
        workgroup_size,
        vertex_inputs,
        defines: variant.defines.clone(),
    })
}

/// Rejects, with their line, the constructs of [`UNREADABLE_BY_NAGA`].
fn check_naga_subset(path: &Path, text: &str) -> Result<(), ShaderError> {
    for (index, line) in text.lines().enumerate() {
        let code = line.split("//").next().unwrap_or("");
        for (needle, what) in UNREADABLE_BY_NAGA {
            // Prefix match at a word start: `sampler2DArray` and `subgroupAdd` count too. A
            // sampler type followed by `(` is the constructor that combines a separate texture
            // and sampler at the use site, which naga reads.
            let found = code.match_indices(needle).any(|(at, _)| {
                let word_start = !code[..at]
                    .chars()
                    .next_back()
                    .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
                let rest =
                    code[at..].trim_start_matches(|c: char| c.is_ascii_alphanumeric() || c == '_');
                let constructor =
                    needle.starts_with("sampler") && rest.trim_start().starts_with('(');
                word_start && !constructor
            });
            if found {
                return Err(ShaderError {
                    file: path.to_path_buf(),
                    line: Some(index as u32 + 1),
                    message: format!(
                        "`{needle}`: naga's SPIR-V reader cannot read {what} (docs/architecture.md, section Shaders)"
                    ),
                });
            }
        }
    }
    Ok(())
}

/// Turns glslang's log (`ERROR: 0:12: …` or `ERROR: sh.glsl:12: …`) into a located error.
fn glslang_error(
    path: &Path,
    include_dir: &Path,
    error: &glslang::error::GlslangError,
) -> ShaderError {
    let log = match error {
        glslang::error::GlslangError::PreprocessError(l)
        | glslang::error::GlslangError::ParseError(l)
        | glslang::error::GlslangError::LinkError(l)
        | glslang::error::GlslangError::MapIoError(l) => l.log.clone(),
        other => other.to_string(),
    };
    let first = log
        .lines()
        .find(|l| l.starts_with("ERROR:"))
        .unwrap_or(log.lines().next().unwrap_or("glslang failed"));
    let mut file = path.to_path_buf();
    let mut line = None;
    let mut message = first.to_string();
    let located = first.strip_prefix("ERROR: ").and_then(|rest| {
        let mut parts = rest.splitn(3, ':');
        let (src, num, msg) = (parts.next()?, parts.next()?, parts.next()?);
        Some((src, num.trim().parse::<u32>().ok()?, msg.trim()))
    });
    if let Some((src, n, msg)) = located {
        // glslang names the main source "0" and includes by their header name.
        if src != "0" && !src.is_empty() {
            file = include_dir.join(src.trim_matches('"'));
        }
        line = Some(n);
        message = msg.to_string();
    }
    let rest: Vec<&str> = log
        .lines()
        .filter(|l| {
            l.starts_with("ERROR:")
                && *l != first
                && !l.contains("compilation errors")
                && !l.contains("compilation terminated")
        })
        .collect();
    if !rest.is_empty() {
        message.push_str("\n  ");
        message.push_str(&rest.join("\n  "));
    }
    ShaderError {
        file,
        line,
        message,
    }
}

/// The line declaring the global a naga message names (`Global variable [3] 'name' …`): the
/// block's closing `} name;` or a `layout(…) … name;` line.
fn declaration_line(text: &str, message: &str) -> Option<u32> {
    let name = message.split('\'').nth(1)?;
    text.lines().enumerate().find_map(|(index, line)| {
        let code = line.split("//").next().unwrap_or("").trim();
        let declares = code.trim_end_matches(';').split_whitespace().last() == Some(name)
            && (code.starts_with('}') || code.starts_with("layout"));
        declares.then_some(index as u32 + 1)
    })
}

/// An error and every `source()` below it, joined: naga nests the useful part deep.
fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut next = error.source();
    while let Some(e) = next {
        text.push_str(": ");
        text.push_str(&e.to_string());
        next = e.source();
    }
    text
}

fn bytemuck_words(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}
