use bsp_compiler::cli::{Args, run};
use clap::Parser;
use std::process::ExitCode;

/// Compile a Quake .map into a BSP (BSP29 or BSP2) and its .prt portal file.
#[derive(Parser)]
#[command(name = "slipgate-bsp", version)]
struct Cli {
    #[command(flatten)]
    args: Args,
}

fn main() -> ExitCode {
    quake_formats::cli::end_quietly_on_closed_pipe();
    let cli = Cli::parse_from(bsp_compiler::cli::join_optional_values(
        quake_formats::cli::normalise_single_dash(std::env::args()),
    ));
    match run(&cli.args) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
