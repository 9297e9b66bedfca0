//! Error of a lit BSP against a reference lit earlier: `compare_lit LIT.bsp REFERENCE.bsp STRIDE`,
//! where REFERENCE.bsp is the same BSP lit with `--reference --face-stride STRIDE`. Compares the
//! grey bytes of every style of those faces, in 8-bit levels, as `--compare-reference` does, so
//! the slow reference is traced once for many runs.

use light::{compare, lightmaps_in};
use quake_formats::Bsp;

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let [lit, reference, stride] = &args[..] else {
        anyhow::bail!("usage: compare_lit LIT.bsp REFERENCE.bsp STRIDE");
    };
    let stride: usize = stride.parse()?;
    anyhow::ensure!(stride > 0, "STRIDE must be at least 1");
    let lit = Bsp::read(&std::fs::read(lit)?)?;
    let reference = Bsp::read(&std::fs::read(reference)?)?;
    let faces: Vec<usize> = (0..reference.faces.len()).step_by(stride).collect();
    let e = compare(
        &lightmaps_in(&lit, &faces),
        &lightmaps_in(&reference, &faces),
    );
    println!(
        "RMSE {:.3}, max {} levels over {} luxels ({} differ by more than 8, {} by more than 2; \
         {} black where the reference is not, {} where it is above 2)",
        e.rmse, e.max, e.luxels, e.over_8, e.over_2, e.black, e.black_over_2
    );
    Ok(())
}
