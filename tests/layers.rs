//! The layering the architecture promises (docs/architecture.md), checked on the source: only src/gpu/ names ash or
//! raw Vulkan (`vk::`), only the binary's command-line code (src/main.rs, src/cli/) names clap, the model layer
//! names no layer above it, and runtime/ no GPU or renderer type.

use std::path::{Path, PathBuf};

fn sources(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            sources(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// Whether `line` has `word` as a whole path segment: not the end of a longer name (`hash::` is not `ash::`).
fn names(line: &str, word: &str) -> bool {
    line.match_indices(word).any(|(at, _)| {
        !line[..at]
            .chars()
            .next_back()
            .is_some_and(|c| c.is_alphanumeric() || c == '_')
    })
}

/// Every source file that `checked` accepts (by its path under the repository) and that contains one of `words`
/// outside comments, with the first such line.
fn offenders_where(words: &[&str], checked: impl Fn(&str) -> bool) -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src"), &mut files);
    assert!(files.len() > 50, "the source tree was not found");
    files
        .iter()
        .filter_map(|path| {
            let relative = path
                .strip_prefix(root)
                .unwrap()
                .to_string_lossy()
                .replace('\\', "/");
            if !checked(&relative) {
                return None;
            }
            let text = std::fs::read_to_string(path).unwrap();
            text.lines()
                .enumerate()
                .filter(|(_, line)| !line.trim_start().starts_with("//"))
                .find(|(_, line)| words.iter().any(|w| names(line, w)))
                .map(|(n, line)| format!("{relative}:{}: {}", n + 1, line.trim()))
        })
        .collect()
}

/// Every source file outside `allowed` (prefixes under src/) that contains one of `words`.
fn offenders(words: &[&str], allowed: &[&str]) -> Vec<String> {
    offenders_where(words, |path| !allowed.iter().any(|a| path.starts_with(a)))
}

/// Every source file inside `layer` (prefixes under src/) that contains one of `words`.
fn offenders_in(layer: &[&str], words: &[&str]) -> Vec<String> {
    offenders_where(words, |path| layer.iter().any(|a| path.starts_with(a)))
}

#[test]
fn the_model_names_no_layer_above_it_and_runtime_no_gpu_type() {
    let model = [
        "src/planet/",
        "src/river/",
        "src/drainage/",
        "src/config/",
        "src/rng.rs",
        "src/fast_hash.rs",
        "src/shader_types.rs",
    ];
    let above = [
        "kernel::",
        "runtime::",
        "render::",
        "gpu::",
        "refine::",
        "bench::",
        "export::",
        "world::",
    ];
    let found = offenders_in(&model, &above);
    assert!(
        found.is_empty(),
        "the model names a layer above it:\n{}",
        found.join("\n")
    );
    let found = offenders_in(
        &["src/runtime/"],
        &["gpu::", "render::", "bench::", "export::"],
    );
    assert!(
        found.is_empty(),
        "runtime names a GPU or renderer type:\n{}",
        found.join("\n")
    );
}

#[test]
fn only_the_gpu_module_names_vulkan() {
    let found = offenders(&["vk::", "ash::", "use ash"], &["src/gpu/"]);
    assert!(
        found.is_empty(),
        "raw Vulkan outside src/gpu:\n{}",
        found.join("\n")
    );
}

#[test]
fn only_the_command_line_names_clap() {
    let found = offenders(&["clap"], &["src/cli/", "src/main.rs"]);
    assert!(
        found.is_empty(),
        "clap outside the command line:\n{}",
        found.join("\n")
    );
}

#[test]
fn a_name_is_found_only_as_a_whole_path_segment() {
    assert!(names("use ash::vk;", "ash::"));
    assert!(names("let x: ash::Device = d;", "ash::"));
    assert!(names("    vk::Format::R8", "vk::"));
    assert!(!names(
        "use std::hash::{BuildHasherDefault, Hasher};",
        "ash::"
    ));
    assert!(!names("let m = mvk::x;", "vk::"));
}

/// The first names of the items of `super::` paths in `code`: `super::a::x` gives `a`, `super::{a, b::y}` gives
/// `a` and `b`.
fn super_names(code: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = Vec::new();
    for (at, _) in code.match_indices("super::") {
        let rest = &code[at + "super::".len()..];
        if let Some(block) = rest.strip_prefix('{') {
            let mut depth = 0;
            let mut start = 0;
            for (i, c) in block.char_indices() {
                match c {
                    '{' => depth += 1,
                    '}' if depth == 0 => {
                        out.push(ident(&block[start..i]));
                        break;
                    }
                    '}' => depth -= 1,
                    ',' if depth == 0 => {
                        out.push(ident(&block[start..i]));
                        start = i + 1;
                    }
                    _ => {}
                }
            }
        } else {
            out.push(ident(rest));
        }
    }
    out
}

/// Pairs of files in one module directory below src/ that name each other through `super::` (outside comments and
/// test modules): a circle means the two concerns are not split where the files say.
fn sibling_circles() -> Vec<String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    sources(&root, &mut files);
    let mut uses: std::collections::BTreeMap<(PathBuf, String), Vec<String>> = Default::default();
    for path in &files {
        let dir = path.parent().unwrap().to_path_buf();
        let stem = path.file_stem().unwrap().to_string_lossy().to_string();
        if dir == root || stem == "mod" {
            continue;
        }
        let text = std::fs::read_to_string(path).unwrap();
        let code: String = text
            .split("#[cfg(test)]")
            .next()
            .unwrap()
            .lines()
            .filter(|l| !l.trim_start().starts_with("//"))
            .collect::<Vec<_>>()
            .join("\n");
        uses.insert((dir, stem), super_names(&code));
    }
    let mut circles = Vec::new();
    for ((dir, a), named) in &uses {
        for b in named.iter().filter(|b| a < *b) {
            if uses
                .get(&(dir.clone(), b.clone()))
                .is_some_and(|back| back.contains(a))
            {
                let dir = dir.strip_prefix(&root).unwrap().display();
                circles.push(format!("src/{dir}/{a}.rs <-> src/{dir}/{b}.rs"));
            }
        }
    }
    circles.sort();
    circles.dedup();
    circles
}

#[test]
fn no_two_files_of_a_module_import_each_other() {
    assert_eq!(
        super_names("use super::{access, memory::{Buffer, Image}, GpuError};\nlet x = super::drainage::f();"),
        ["access", "memory", "GpuError", "drainage"]
    );
    let circles = sibling_circles();
    assert!(
        circles.is_empty(),
        "import circles:\n{}",
        circles.join("\n")
    );
}

#[test]
fn the_gpu_module_exposes_no_raw_handle() {
    let handles = [
        "vk::Image,",
        "vk::ImageView,",
        "vk::Buffer,",
        "vk::Pipeline,",
        "vk::PipelineLayout,",
        "vk::CommandBuffer,",
        "vk::SwapchainKHR,",
        "vk::SurfaceKHR,",
        "vk::PhysicalDevice,",
        "ash::Device,",
        "ash::Instance,",
        "ash::Entry,",
        "Vec<vk::Image>,",
        "Vec<vk::ImageView>,",
    ];
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    sources(&root.join("src/gpu"), &mut files);
    let mut found = Vec::new();
    for path in &files {
        let text = std::fs::read_to_string(path).unwrap();
        for (n, line) in text.lines().enumerate() {
            let line = line.trim();
            let public_field = line.starts_with("pub ")
                && line
                    .split_once(':')
                    .is_some_and(|(_, ty)| handles.contains(&ty.trim()));
            if public_field || line == "pub use ash::vk;" {
                found.push(format!("{}:{}: {line}", path.display(), n + 1));
            }
        }
    }
    assert!(
        found.is_empty(),
        "public raw handles in src/gpu (keep them pub(super)):\n{}",
        found.join("\n")
    );
}
