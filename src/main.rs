//! `slipgate`: the one command. Each subcommand is a thin shell over a library stage.

mod allocator;
mod build;
mod decompile;
mod inspect;
mod report;

use anyhow::Result;
use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[global_allocator]
static ALLOCATOR: allocator::MiMalloc = allocator::MiMalloc;

#[derive(Parser, Debug)]
#[command(
    name = "slipgate",
    version = concat!(env!("CARGO_PKG_VERSION"), " (", env!("SLIPGATE_COMMIT"), ")"),
    about = "Compile Quake .map files to BSP (qbsp, vis, light) and preview them",
    long_about = "Compile Quake .map files to BSP29/BSP2 (qbsp, vis, light) and preview them with a \
                  software renderer.\n\nericw-tools' single-dash spellings (-bsp2, -fast, -extra4, \
                  -soft, ...) are accepted as aliases of the double-dash options."
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Build a map start to finish: bsp, vis, light, and a PNG preview
    Build(build::BuildArgs),
    /// Compile a .map to BSP29 (or BSP2), writing the .prt portal file and a .pts pointfile on a leak
    Bsp(Box<bsp_compiler::cli::Args>),
    /// Compute the potentially visible set of every leaf from the .prt portals (--fast: base vis only)
    Vis(vis::cli::Args),
    /// Compute lightmaps with Embree-traced shadow rays (writes the BSP, and .lit for coloured light)
    Light(light::cli::Args),
    /// Render a compiled map to PNG with the software renderer (or fly through it with --bench)
    View(runtime_viewer::cli::Args),
    /// Print a BSP's lump counts and sizes and validate it (exit 1 when it has errors)
    Info(inspect::InfoArgs),
    /// Rewrite a BSP (optionally as BSP29 or BSP2) or a WAD; unchanged data is byte-identical
    Convert(inspect::ConvertArgs),
    /// Time every stage at every quality setting and measure its error against its reference
    Report(report::ReportArgs),
    /// Build many maps (a project file or a folder): cached, in parallel, optionally in shards
    Batch(batch::cli::Args),
    /// Texture WADs: build one from a folder of PNG/TGA pictures, list one, extract its pictures
    Wad(wad::cli::Args),
    /// Turn a compiled BSP back into a .map (ericw-tools' bsputil --decompile)
    Decompile(decompile::DecompileArgs),
}

unsafe extern "C" {
    /// mimalloc's `mi_option_set` (mimalloc.h), in the library the allocator links.
    fn mi_option_set(option: std::ffi::c_int, value: std::ffi::c_long);
}

/// `mi_option_purge_delay` in mimalloc.h's `mi_option_t` (the same in its versions 2 and 3).
const MI_OPTION_PURGE_DELAY: std::ffi::c_int = 15;

/// Whether freed memory stays with the process until it ends, or goes back to the system at once.
/// The compiler and light free and take back buffers of the same sizes face after face, and
/// memory given back to the system comes back zeroed by the kernel, page by page (huge pages
/// included), each time it is taken again: they keep it. Vis frees the states of one portal's
/// flow, of sizes later flows seldom ask for again: kept, they would stay on top of its peak.
pub(crate) fn keep_freed_memory(keep: bool) {
    // SAFETY: setting an option is allowed at any time; -1 is its documented "never purge",
    // 0 "purge at once".
    unsafe { mi_option_set(MI_OPTION_PURGE_DELAY, if keep { -1 } else { 0 }) };
}

fn main() -> ExitCode {
    quake_formats::cli::end_quietly_on_closed_pipe();
    let cli = Cli::parse_from(batch::command_words(std::env::args()));
    keep_freed_memory(!matches!(cli.command, Command::Vis(_)));
    let result = run(cli.command);
    // No thread may still be freeing light's Embree scenes while the process ends.
    light::wait_for_background_frees();
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::from(1)
        }
    }
}

fn run(command: Command) -> Result<ExitCode> {
    match command {
        Command::Build(args) => build::build(&args).map(|()| ExitCode::SUCCESS),
        Command::Bsp(args) => bsp_compiler::cli::run(&args).map(|_| ExitCode::SUCCESS),
        Command::Vis(args) => vis::cli::run(&args).map(|_| ExitCode::SUCCESS),
        Command::Light(args) => light::cli::run(&args).map(|_| ExitCode::SUCCESS),
        Command::View(args) => runtime_viewer::cli::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Info(args) => inspect::info(&args),
        Command::Convert(args) => inspect::convert(&args).map(|()| ExitCode::SUCCESS),
        Command::Report(args) => report::report(&args).map(|()| ExitCode::SUCCESS),
        Command::Batch(args) => batch::cli::run(&args),
        Command::Wad(args) => wad::cli::run(&args).map(|()| ExitCode::SUCCESS),
        Command::Decompile(args) => decompile::decompile(&args).map(|()| ExitCode::SUCCESS),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ericw_spellings_of_compiler_options_parse() {
        let args = [
            "slipgate",
            "bsp",
            "-leaktest",
            "-notex",
            "-nofill",
            "-keepprt",
            "-noclip",
            "-omitdetail",
            "-nosubdivide",
            "-maxnodesize",
            "512",
            "-wrbrushes",
            "-onlyents",
            "-convert",
            "valve",
            "x.map",
        ];
        let cli = Cli::try_parse_from(batch::command_words(args.iter().map(|s| s.to_string())))
            .expect("parse");
        let Command::Bsp(bsp) = cli.command else {
            panic!("not the bsp command");
        };
        let options = bsp.compile_options();
        assert!(bsp.leaktest && bsp.keepprt);
        assert!(!options.texture_data && !options.fill && !options.clip_hulls);
        assert_eq!(options.omit, ["func_detail"]);
        assert_eq!((options.subdivide, options.max_node_size), (0.0, 512.0));
        assert!(options.brush_list && bsp.onlyents);
        assert_eq!(bsp.convert, Some(bsp_compiler::convert::MapFormat::Valve));
    }
}
