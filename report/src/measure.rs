//! Each stage's answer against its slow exact reference, measured with the libraries, the same
//! way whichever tool wrote the file.

use std::path::Path;

use light::{
    DrawnAreas, Lighting, Options, Quality, compare, compare_drawn, compare_grids, finish_lighting,
    lightmaps_in, own_grid_lightmaps_in, own_grids, trace_lighting,
};
use quake_formats::Bsp;
use quake_formats::bsp::lightgrid::LightGrid;
use quake_formats::prt::PortalFile;
use runtime_viewer::{Comparison, ViewSummary};

use crate::ReportError;
use crate::settings::LightMeasure;

pub fn read_bsp(path: &Path) -> Result<Bsp, ReportError> {
    let bytes = std::fs::read(path).map_err(ReportError::io(path))?;
    Bsp::read(&bytes).map_err(|source| ReportError::Format {
        path: path.to_path_buf(),
        source,
    })
}

/// A compiled BSP's counts and the cracks the crack checker finds in it.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct BspFigures {
    /// Faces in the BSP.
    pub faces: usize,
    /// Leaves in the BSP, leaf 0 included.
    pub leaves: usize,
    /// Hull 0 nodes.
    pub nodes: usize,
    /// Clip nodes of hulls 1 and 2.
    pub clipnodes: usize,
    /// Portals in the `.prt` file beside the BSP.
    pub portals: usize,
    /// Entries of the marksurfaces lump.
    pub marksurfaces: usize,
    /// Size of the BSP file in bytes.
    pub file_bytes: u64,
    /// Vertices lying inside another face's edge.
    pub tjunctions: usize,
    /// Directed edges used by more than two faces, and by more or fewer than their reverse.
    pub overused_edges: usize,
    /// Pairs of vertex indices of one model at the same position.
    pub duplicate_vertices: usize,
    /// Player-box (hull 1) moves traced through the clip hull and through the map's brushes.
    pub hull_traces: usize,
    /// Moves whose two stops are further apart than `HULL_AGREEMENT_TOLERANCE`.
    pub hull_disagreements: usize,
    /// The largest gap between the two stops of any move, in units.
    pub hull_worst_gap: f64,
}

impl BspFigures {
    /// Everything that would show as a crack: T-junctions, overused edges and duplicate
    /// vertices.
    pub fn cracks(&self) -> usize {
        self.tjunctions + self.overused_edges + self.duplicate_vertices
    }
}

/// The map's brushes as the compiler reads them (prefabs expanded), for the hull check.
fn read_map(path: &Path) -> Result<bsp_compiler::map::MapFile, ReportError> {
    let failed = |what: String| ReportError::Measure {
        path: path.to_path_buf(),
        what,
    };
    let text = bsp_compiler::map::read_map_text(path).map_err(ReportError::io(path))?;
    let map = bsp_compiler::map::parse_map(path, &text).map_err(|e| failed(e.to_string()))?;
    bsp_compiler::prefab::expand_prefabs(map, path).map_err(|e| failed(e.to_string()))
}

/// Counts, cracks and hull agreement of the BSP compiled from `map_path`.
pub fn bsp_figures(
    bsp_path: &Path,
    map_path: &Path,
    hull_traces: usize,
) -> Result<BspFigures, ReportError> {
    let bsp = read_bsp(bsp_path)?;
    let prt_path = bsp_path.with_extension("prt");
    let prt_text = std::fs::read(&prt_path).map_err(ReportError::io(&prt_path))?;
    let prt = PortalFile::parse(&String::from_utf8_lossy(&prt_text)).map_err(|source| {
        ReportError::Format {
            path: prt_path.clone(),
            source,
        }
    })?;
    let cracks = bsp_compiler::cracks::find_cracks(&bsp);
    let options = bsp_compiler::hull_check::HullCheckOptions {
        traces: hull_traces,
        ..Default::default()
    };
    let hull = bsp_compiler::hull_check::hull_agreement(&read_map(map_path)?, &bsp, &options)
        .map_err(|e| ReportError::Measure {
            path: bsp_path.to_path_buf(),
            what: format!("hull check: {e}"),
        })?;
    Ok(BspFigures {
        faces: bsp.faces.len(),
        leaves: bsp.leafs.len(),
        nodes: bsp.nodes.len(),
        clipnodes: bsp.clipnodes.len(),
        portals: prt.portals.len(),
        marksurfaces: bsp.marksurfaces.len(),
        file_bytes: std::fs::metadata(bsp_path)
            .map_err(ReportError::io(bsp_path))?
            .len(),
        tjunctions: cracks.tjunctions.len(),
        overused_edges: cracks.overused_edges.len(),
        duplicate_vertices: cracks.duplicate_vertices.len(),
        hull_traces: hull.traces,
        hull_disagreements: hull.disagreements,
        hull_worst_gap: hull.worst_gap,
    })
}

/// A vised BSP's PVS against sight lines sampled through its hull 0.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct VisFigures {
    /// Leaves the PVS has rows for.
    pub leaves: usize,
    /// Leaves each leaf's PVS holds, on average.
    pub average_visible: f64,
    /// Random point pairs in open leaves whose sight line was traced.
    pub sampled_pairs: usize,
    /// Sampled pairs with a clear line of sight.
    pub clear_pairs: usize,
    /// Clear pairs missing from the PVS: must be 0.
    pub seen_not_in_pvs: usize,
    /// Share of sampled pairs the PVS holds over the share sight lines show visible: how much
    /// larger than the sampled set the PVS is (1 = as tight as sampling can tell).
    pub pvs_over_sampled: f64,
}

/// The seed of the sight-line sampling, the same for every tool and setting.
const SAMPLING_SEED: u64 = 1;

pub fn vis_figures(bsp_path: &Path, pairs: usize) -> Result<VisFigures, ReportError> {
    let bsp = read_bsp(bsp_path)?;
    let vis_error = |source| ReportError::Vis {
        path: bsp_path.to_path_buf(),
        source,
    };
    let pvs = vis::lump::read_pvs(&bsp).map_err(vis_error)?;
    let s = vis::sample::sample_visibility(&bsp, &pvs, pairs, SAMPLING_SEED).map_err(vis_error)?;
    Ok(VisFigures {
        leaves: pvs.num_leafs(),
        average_visible: pvs.average_visible(),
        sampled_pairs: s.pairs,
        clear_pairs: s.clear_pairs,
        seen_not_in_pvs: s.violations,
        pvs_over_sampled: if s.visible_fraction > 0.0 {
            s.pvs_fraction / s.visible_fraction
        } else {
            0.0
        },
    })
}

/// Light's references of one BSP on every Nth face, each taken the first time a setting asks
/// for it.
pub struct LightReferences {
    pub face_stride: usize,
    pub faces: Vec<usize>,
    /// Each reference taken: what it measures, its lighting and its seconds.
    pub taken: Vec<(LightMeasure, Lighting, f64)>,
    bsp: Bsp,
    bsp_path: std::path::PathBuf,
}

impl LightReferences {
    /// References of about `faces_wanted` faces of `bsp_path` (every Nth face).
    pub fn new(bsp_path: &Path, faces_wanted: usize) -> Result<LightReferences, ReportError> {
        let bsp = read_bsp(bsp_path)?;
        let face_stride = bsp.faces.len().div_ceil(faces_wanted.max(1)).max(1);
        let faces: Vec<usize> = (0..bsp.faces.len()).step_by(face_stride).collect();
        Ok(LightReferences {
            face_stride,
            faces,
            taken: Vec::new(),
            bsp,
            bsp_path: bsp_path.to_path_buf(),
        })
    }

    /// The reference a setting's `measure` is measured against.
    pub fn for_measure(&mut self, measure: LightMeasure) -> Result<&Lighting, ReportError> {
        let at = match self.taken.iter().position(|(m, ..)| *m == measure) {
            Some(at) => at,
            None => {
                let (lighting, seconds) =
                    reference(&self.bsp, &self.bsp_path, &self.faces, measure)?;
                self.taken.push((measure, lighting, seconds));
                self.taken.len() - 1
            }
        };
        Ok(&self.taken[at].1)
    }
}

/// Light's reference of `faces` for `measure` (the light grid's samples no face), and its
/// seconds.
fn reference(
    bsp: &Bsp,
    path: &Path,
    faces: &[usize],
    measure: LightMeasure,
) -> Result<(Lighting, f64), ReportError> {
    let mut options = Options {
        quality: Quality::Reference,
        only_faces: Some(faces.to_vec()),
        ..Options::default()
    };
    match measure {
        LightMeasure::Lightmaps { bounce } => options.overrides.bounce = bounce.then_some(1),
        LightMeasure::OwnGrids {
            world_units_per_luxel,
        } => options.overrides.world_units_per_luxel = Some(world_units_per_luxel),
        LightMeasure::LightGrid => {
            options.overrides.lightgrid = Some(true);
            options.only_faces = Some(Vec::new());
        }
    }
    let start = std::time::Instant::now();
    let raw = trace_lighting(bsp, &options).map_err(|source| ReportError::Light {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((finish_lighting(&raw), start.elapsed().as_secs_f64()))
}

/// A lit BSP's light against light's reference, in 8-bit grey levels, over the luxels engines
/// draw of the faces the reference lit, each weighted by the area of the face it shows on (for
/// the light grid: over each style of each grid point open in both grids, alike).
#[derive(Debug, Clone, serde::Serialize)]
pub struct LightFigures {
    /// What was compared.
    pub measured: LightMeasure,
    /// Luxels (or grid samples) compared.
    pub luxels: u64,
    /// Root mean square difference from the reference, in levels.
    pub rmse: f64,
    /// Largest difference from the reference, in levels.
    pub max: u8,
    /// Share of luxels more than 2 levels off (0 to 1).
    pub over_2_share: f64,
    /// Root mean square difference over every luxel of the lightmaps, those no engine draws
    /// (inside solid, past a triangle's corners) included; `None` for the light grid.
    pub whole_lightmaps_rmse: Option<f64>,
    /// What sampling the light grid cost the run, when it sampled one and said so (Slipgate's
    /// `--stats`).
    pub grid_cost: Option<GridCost>,
}

/// What sampling the light grid cost one light run, from its own timings.
#[derive(Debug, Clone, Copy, serde::Serialize)]
pub struct GridCost {
    /// Grid points.
    pub points: u64,
    /// Grid points in the open (the rest are in solid).
    pub open_points: u64,
    /// Seconds sampling the grid.
    pub seconds: f64,
    /// Seconds lighting the faces (direct and bounced light) in the same run.
    pub lightmap_seconds: f64,
    /// The grid's share of the run's whole time in light (setup, faces, grid), 0 to 1.
    pub share: f64,
}

/// The figures of light's `--stats` file that give the grid's cost.
#[derive(serde::Deserialize)]
struct LightRunStats {
    grid_points: u64,
    grid_points_open: u64,
    seconds_lightgrid: f64,
    seconds_trace: f64,
    seconds_bounce: f64,
    seconds_total: f64,
}

/// The grid's cost from the `--stats` file light wrote at `path`; `None` when it sampled no
/// grid.
pub fn grid_cost(path: &Path) -> Result<Option<GridCost>, ReportError> {
    let text = std::fs::read(path).map_err(ReportError::io(path))?;
    let s: LightRunStats = serde_json::from_slice(&text).map_err(|e| ReportError::Measure {
        path: path.to_path_buf(),
        what: e.to_string(),
    })?;
    Ok((s.grid_points > 0).then(|| GridCost {
        points: s.grid_points,
        open_points: s.grid_points_open,
        seconds: s.seconds_lightgrid,
        lightmap_seconds: s.seconds_trace + s.seconds_bounce,
        share: s.seconds_lightgrid / s.seconds_total.max(f64::MIN_POSITIVE),
    }))
}

/// The light of `lit_path` that `measure` names against `reference` (its reference).
pub fn light_figures(
    lit_path: &Path,
    measure: LightMeasure,
    reference: &Lighting,
) -> Result<LightFigures, ReportError> {
    let lit = read_bsp(lit_path)?;
    let cannot = |what: &str| ReportError::Measure {
        path: lit_path.to_path_buf(),
        what: what.into(),
    };
    let faces: Vec<usize> = reference.lightmaps.iter().map(|m| m.face).collect();
    let (e, whole) = match measure {
        LightMeasure::Lightmaps { .. } => {
            let ours = lightmaps_in(&lit, &faces);
            let drawn = DrawnAreas::on_quake_grids(&lit, &faces);
            (
                compare_drawn(&ours, reference, &drawn),
                Some(compare(&ours, reference)),
            )
        }
        LightMeasure::OwnGrids { .. } => {
            let ours =
                own_grid_lightmaps_in(&lit, &faces).map_err(|source| ReportError::Light {
                    path: lit_path.to_path_buf(),
                    source,
                })?;
            let exact = own_grids(reference)
                .ok_or_else(|| cannot("the reference lit no face on its own grid"))?;
            let drawn = DrawnAreas::on_own_grids(&lit, reference);
            (
                compare_drawn(&ours, &exact, &drawn),
                Some(compare(&ours, &exact)),
            )
        }
        LightMeasure::LightGrid => {
            let grid = lit.light_grid().map_err(|source| ReportError::Format {
                path: lit_path.to_path_buf(),
                source,
            })?;
            let grid = grid.ok_or_else(|| cannot("no LIGHTGRID_OCTREE lump"))?;
            let exact = (reference.light_grid.as_ref())
                .ok_or_else(|| cannot("the reference sampled no light grid"))?;
            let points = |g: &LightGrid| {
                format!(
                    "{:?} apart from {:?}, {:?} of them",
                    g.spacing, g.mins, g.size
                )
            };
            let e = compare_grids(&grid, exact).ok_or_else(|| {
                cannot(&format!(
                    "its light grid's points ({}) are not the reference's ({})",
                    points(&grid),
                    points(exact)
                ))
            })?;
            (e, None)
        }
    };
    if e.luxels == 0 {
        return Err(cannot(&format!(
            "no {} in common with the reference",
            measure.counted()
        )));
    }
    Ok(LightFigures {
        measured: measure,
        luxels: e.luxels,
        rmse: e.rmse,
        max: e.max,
        over_2_share: e.over_2 as f64 / e.luxels as f64,
        whole_lightmaps_rmse: whole.map(|w| w.rmse),
        grid_cost: None,
    })
}

/// The viewer's flythrough speed and its picture against the exact ray-cast renderer.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct ViewFigures {
    /// Pixels between exact perspective divides in this setting.
    pub span_step: u32,
    /// Best flythrough frame rate over the runs.
    pub fps: f64,
    /// Mean per-channel difference from the reference picture (of 255).
    pub mean_diff: f64,
    /// Largest per-channel difference from the reference picture (of 255).
    pub max_diff: f64,
    /// Share of pixels that show another face than the reference's.
    pub face_mismatch: f64,
}

/// What `slipgate view --stats` wrote to `path`.
fn view_summary(path: &Path) -> Result<ViewSummary, ReportError> {
    let text = std::fs::read(path).map_err(ReportError::io(path))?;
    serde_json::from_slice(&text).map_err(|e| ReportError::Measure {
        path: path.to_path_buf(),
        what: e.to_string(),
    })
}

/// A part of the viewer's summary at `path` that the run asked for and that is not there.
fn missing(path: &Path, what: &str) -> ReportError {
    ReportError::Measure {
        path: path.to_path_buf(),
        what: format!("the viewer wrote no {what}"),
    }
}

/// The frame rate of the flythrough the viewer's summary at `path` records.
pub fn flythrough_fps(path: &Path) -> Result<f64, ReportError> {
    let bench = view_summary(path)?.bench;
    Ok(bench.ok_or_else(|| missing(path, "flythrough"))?.fps)
}

/// The picture against the reference renderer's, from the viewer's summary at `path`.
pub fn reference_comparison(path: &Path) -> Result<Comparison, ReportError> {
    let reference = view_summary(path)?.reference;
    reference.ok_or_else(|| missing(path, "comparison with the reference"))
}
