//! The layering the architecture promises (docs/architecture.md), checked on the source: only src/gpu/ names ash or
//! raw Vulkan (`vk::`), and only the binary's command-line code (src/main.rs, src/cli/) names clap.

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

/// Every source file outside `allowed` (prefixes under src/) that contains one of `words`, with the first line.
fn offenders(words: &[&str], allowed: &[&str]) -> Vec<String> {
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
            if allowed.iter().any(|a| relative.starts_with(a)) {
                return None;
            }
            let text = std::fs::read_to_string(path).unwrap();
            text.lines()
                .enumerate()
                .find(|(_, line)| words.iter().any(|w| line.contains(w)))
                .map(|(n, line)| format!("{relative}:{}: {}", n + 1, line.trim()))
        })
        .collect()
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
