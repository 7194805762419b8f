//! The build-time shader pipeline (build/shader_build.rs, the module build.rs runs) on small
//! shader trees: good shaders reflect correctly; bad ones fail naming their file and line.

#[allow(dead_code)]
#[path = "../build/shader_build.rs"]
mod shader_build;

use shader_build::{DescriptorKind, build_all};
use std::path::{Path, PathBuf};

/// A throw-away shaders/ tree under the target directory.
struct Tree(PathBuf);

impl Tree {
    fn new(name: &str) -> Self {
        let root = Path::new(env!("CARGO_TARGET_TMPDIR"))
            .join("shader_build")
            .join(name);
        let _ = std::fs::remove_dir_all(&root);
        std::fs::create_dir_all(root.join("include")).expect("create tree");
        Self(root)
    }

    fn file(&self, path: &str, text: &str) -> &Self {
        let path = self.0.join(path);
        std::fs::create_dir_all(path.parent().expect("parent")).expect("create dir");
        std::fs::write(path, text).expect("write shader");
        self
    }
}

const GOOD: &str = r#"#version 460
#extension GL_GOOGLE_include_directive : require
//! variant small N=2
//! variant large N=8
#include "common.glsl"
layout(local_size_x = 8, local_size_y = 4) in;
layout(set = 0, binding = 0, std430) readonly buffer In { float v[]; } src;
layout(set = 1, binding = 2, rgba16f) uniform writeonly image2D dst;
layout(set = 1, binding = 3) uniform texture2D tex;
layout(set = 1, binding = 4) uniform sampler smp;
layout(push_constant) uniform Push { vec4 a; uint b; } push;
void main() {
    float x = twice(src.v[gl_GlobalInvocationID.x]) * float(N) + push.a.x + float(push.b);
    x += textureLod(sampler2D(tex, smp), vec2(0.5), 0.0).r;
    imageStore(dst, ivec2(gl_GlobalInvocationID.xy), vec4(x));
}
"#;

#[test]
fn reflects_bindings_push_constants_workgroup_and_variants() {
    let tree = Tree::new("good");
    tree.file(
        "include/common.glsl",
        "float twice(float x) { return 2.0 * x; }\n",
    )
    .file("nested/good.comp", GOOD);
    let output = build_all(&tree.0).expect("good tree builds");
    let names: Vec<_> = output.shaders.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["nested/good.comp:small", "nested/good.comp:large"]);
    let s = &output.shaders[0];
    assert_eq!(s.ident, "NESTED_GOOD_COMP_SMALL");
    assert_eq!(s.workgroup_size, [8, 4, 1]);
    // std430 block size: vec4 + uint = 20 bytes, rounded up to the block's 16-byte alignment.
    assert_eq!(s.push_constant_size, 32);
    let kinds: Vec<_> = s
        .bindings
        .iter()
        .map(|b| (b.set, b.binding, b.name.as_str(), b.kind))
        .collect();
    assert_eq!(
        kinds,
        [
            (
                0,
                0,
                "src",
                DescriptorKind::StorageBuffer { writable: false }
            ),
            (1, 2, "dst", DescriptorKind::StorageImage { writable: true }),
            (1, 3, "tex", DescriptorKind::SampledImage),
            (1, 4, "smp", DescriptorKind::Sampler),
        ]
    );
    assert!(
        output
            .inputs
            .iter()
            .any(|p| p.ends_with("include/common.glsl"))
    );
    assert_ne!(
        output.shaders[0].spirv, output.shaders[1].spirv,
        "variants differ"
    );
}

#[test]
fn reflects_vertex_inputs() {
    let tree = Tree::new("vertex");
    tree.file(
        "mesh.vert",
        "#version 460\nlayout(location = 0) in vec3 pos;\nlayout(location = 2) in vec2 uv;\n\
         layout(location = 0) out vec2 v_uv;\nvoid main() { v_uv = uv; gl_Position = vec4(pos, 1.0); }\n",
    );
    let output = build_all(&tree.0).expect("vertex shader builds");
    let inputs: Vec<_> = output.shaders[0]
        .vertex_inputs
        .iter()
        .map(|i| (i.location, i.format))
        .collect();
    assert_eq!(inputs, [(0, "R32G32B32_SFLOAT"), (2, "R32G32_SFLOAT")]);
}

fn error_of(tree: &Tree) -> String {
    match build_all(&tree.0) {
        Ok(_) => panic!("the bad tree built"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn syntax_error_names_file_and_line() {
    let tree = Tree::new("syntax");
    tree.file(
        "broken.comp",
        "#version 460\nlayout(local_size_x = 1) in;\nvoid main() {\n    float x = 1.0\n}\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("broken.comp:5:"), "{message}");
}

#[test]
fn error_in_an_include_names_the_include() {
    let tree = Tree::new("include");
    tree.file(
        "include/bad.glsl",
        "float f() {\n    return undefined_name;\n}\n",
    )
    .file(
        "user.comp",
        "#version 460\n#extension GL_GOOGLE_include_directive : require\n#include \"bad.glsl\"\n\
             layout(local_size_x = 1) in;\nvoid main() {}\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("bad.glsl:2:"), "{message}");
    assert!(message.contains("undefined_name"), "{message}");
}

#[test]
fn combined_sampler_is_rejected_with_its_line() {
    let tree = Tree::new("combined");
    tree.file(
        "combined.frag",
        "#version 460\nlayout(location = 0) out vec4 o;\n\
         layout(set = 0, binding = 0) uniform sampler2D tex;\nvoid main() { o = texture(tex, vec2(0.0)); }\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("combined.frag:3:"), "{message}");
    assert!(message.contains("sampler2D"), "{message}");
}

#[test]
fn subgroup_ops_are_rejected_with_their_line() {
    let tree = Tree::new("subgroup");
    tree.file(
        "wave.comp",
        "#version 460\n#extension GL_KHR_shader_subgroup_arithmetic : require\nlayout(local_size_x = 8) in;\n\
         void main() { float s = subgroupAdd(1.0); }\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("wave.comp:2:"), "{message}");
}

#[test]
fn naga_validation_error_points_at_the_declaration() {
    // naga's validator refuses write-only storage buffers: the error names the block's line.
    let tree = Tree::new("writeonly");
    tree.file(
        "wo.comp",
        "#version 460\nlayout(local_size_x = 1) in;\n\
         layout(set = 0, binding = 0, std430) writeonly buffer Out {\n    float v[];\n} out_buf;\n\
         void main() { out_buf.v[0] = 1.0; }\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("wo.comp:5:"), "{message}");
    assert!(message.contains("naga"), "{message}");
}

#[test]
fn malformed_variant_line_is_located() {
    let tree = Tree::new("variant");
    tree.file(
        "v.comp",
        "#version 460\n//! variant bad-name X=1\nlayout(local_size_x = 1) in;\nvoid main() {}\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("v.comp:2:"), "{message}");
}

#[test]
fn unreadable_construct_in_an_include_names_the_include() {
    let tree = Tree::new("include_subset");
    tree.file(
        "include/atomics.glsl",
        "// shared helpers\nvoid bump(uint x) {\n    uint y = imageAtomicAdd(x);\n}\n",
    )
    .file(
        "user.comp",
        "#version 460\n#extension GL_GOOGLE_include_directive : require\n#include \"atomics.glsl\"\n\
         layout(local_size_x = 1) in;\nvoid main() {}\n",
    );
    let message = error_of(&tree);
    assert!(message.contains("atomics.glsl:3:"), "{message}");
    assert!(message.contains("imageAtomic"), "{message}");
}

#[test]
fn colliding_names_are_reported() {
    let tree = Tree::new("collide");
    let shader = "#version 460\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
    tree.file("a_b.comp", shader).file("a/b.comp", shader);
    let message = error_of(&tree);
    assert!(message.contains("A_B_COMP"), "{message}");
}
