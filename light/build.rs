//! Links the system Embree 3 library (Debian `libembree-dev` ships no
//! pkg-config file, so we name the library directly).

fn main() {
    println!("cargo::rerun-if-changed=build.rs");
    println!("cargo::rustc-link-lib=dylib=embree3");
}
