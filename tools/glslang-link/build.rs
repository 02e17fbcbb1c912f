//! Debian ships glslang and SPIRV-Tools as separate static archives, and its libshaderc_combined.a is not combined
//! (see ../shared/ENVIRONMENT.md). Link directives only reach the crates that depend on the package that emits
//! them, so this crate exists to put them on riverplanet's *build script*, which runs shaderc.

const LIBS: [&str; 8] = [
    "glslang",
    "MachineIndependent",
    "OSDependent",
    "GenericCodeGen",
    "OGLCompiler",
    "SPIRV",
    "SPIRV-Tools-opt",
    "SPIRV-Tools",
];

fn main() {
    let dir =
        std::env::var("SHADERC_LIB_DIR").unwrap_or_else(|_| "/usr/lib/x86_64-linux-gnu".into());
    println!("cargo:rerun-if-env-changed=SHADERC_LIB_DIR");
    println!("cargo:rustc-link-search=native={dir}");
    for lib in LIBS {
        println!("cargo:rustc-link-lib=static={lib}");
    }
}
