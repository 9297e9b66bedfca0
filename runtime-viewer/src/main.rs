use clap::Parser;
use runtime_viewer::cli::Args;

/// Render a compiled Quake map (BSP29/BSP2) with Slipgate's software renderer.
#[derive(Parser)]
#[command(name = "slipgate-view", version)]
struct Cli {
    #[command(flatten)]
    args: Args,
}

fn main() {
    quake_formats::cli::end_quietly_on_closed_pipe();
    let cli = Cli::parse();
    if let Err(e) = runtime_viewer::cli::run(&cli.args) {
        eprintln!("error: {e:#}");
        std::process::exit(1);
    }
}
