//! `slipgate-light`: light a BSP.

use clap::Parser;

#[derive(Parser)]
#[command(
    name = "slipgate-light",
    version,
    about = "Compute lightmaps for a Quake BSP"
)]
struct Cli {
    #[command(flatten)]
    args: light::cli::Args,
}

fn main() {
    quake_formats::cli::end_quietly_on_closed_pipe();
    let cli = Cli::parse_from(light::cli::join_optional_values(
        quake_formats::cli::normalise_single_dash(std::env::args()),
    ));
    if let Err(e) = light::cli::run(&cli.args) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
