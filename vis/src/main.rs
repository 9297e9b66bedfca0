use clap::Parser;
use std::process::ExitCode;
use vis::cli::{Args, run};

/// Compute the potentially visible sets of a compiled Quake map.
#[derive(Parser)]
#[command(name = "slipgate-vis", version)]
struct Cli {
    #[command(flatten)]
    args: Args,
}

fn main() -> ExitCode {
    quake_formats::cli::end_quietly_on_closed_pipe();
    match run(&Cli::parse_from(quake_formats::cli::normalise_single_dash(std::env::args())).args) {
        Ok(_) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
