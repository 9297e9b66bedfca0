use clap::Parser;
use mapgen::cli::{Args, run};
use std::process::ExitCode;

/// Regenerate Slipgate's demo maps, test maps and texture WAD.
#[derive(Parser)]
#[command(name = "mapgen", version)]
struct Cli {
    #[command(flatten)]
    args: Args,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(&cli.args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}
