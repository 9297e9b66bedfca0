//! Compile a map (or read a BSP) and print its decompiled text: `cargo run -p
//! slipgate-decompile --example decompile_map -- FILE.map|FILE.bsp [valve]`.

use bsp_compiler::{CompileOptions, MapSource, compile};
use decompile::{MapFormat, Options, decompile};
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let Some(path) = args.get(1).map(Path::new) else {
        eprintln!("usage: decompile_map FILE.map|FILE.bsp [valve]");
        std::process::exit(2);
    };
    let bsp = if path.extension().is_some_and(|e| e == "bsp") {
        let bytes = std::fs::read(path).expect("read");
        quake_formats::Bsp::read(&bytes).expect("bsp")
    } else {
        let maps = Path::new(env!("CARGO_MANIFEST_DIR")).join("../maps");
        let options = CompileOptions {
            wad_dirs: vec![maps],
            ..CompileOptions::default()
        };
        compile(&MapSource::read(path).expect("map"), &options)
            .expect("compile")
            .bsp
    };
    let options = Options {
        format: if args.get(2).is_some_and(|a| a == "valve") {
            MapFormat::Valve
        } else {
            MapFormat::Quake
        },
        ..Options::default()
    };
    let out = decompile(&bsp, &options).expect("decompile");
    print!("{}", out.text);
    eprintln!("{:?}", out.stats);
    for w in out.warnings {
        eprintln!("warning: {w}");
    }
}
