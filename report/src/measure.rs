//! Each stage's answer against its slow exact reference, measured with the libraries, the same
//! way whichever tool wrote the file.

use std::path::Path;

use light::{Lighting, Options, Quality, compare, finish_lighting, lightmaps_in, trace_lighting};
use quake_formats::Bsp;
use quake_formats::prt::PortalFile;
use runtime_viewer::{Comparison, ViewSummary};

use crate::ReportError;

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

/// Light's references of one BSP on every Nth face: direct light, and with one bounce.
pub struct LightReferences {
    pub face_stride: usize,
    pub faces: Vec<usize>,
    pub direct: Lighting,
    pub seconds_direct: f64,
    /// Computed the first time a bouncing setting asks for it.
    pub bounce: Option<(Lighting, f64)>,
    bsp: Bsp,
    bsp_path: std::path::PathBuf,
}

impl LightReferences {
    /// The direct reference of about `faces_wanted` faces of `bsp_path` (every Nth face).
    pub fn new(bsp_path: &Path, faces_wanted: usize) -> Result<LightReferences, ReportError> {
        let bsp = read_bsp(bsp_path)?;
        let face_stride = bsp.faces.len().div_ceil(faces_wanted.max(1)).max(1);
        let faces: Vec<usize> = (0..bsp.faces.len()).step_by(face_stride).collect();
        let (direct, seconds_direct) = reference(&bsp, bsp_path, &faces, false)?;
        Ok(LightReferences {
            face_stride,
            faces,
            direct,
            seconds_direct,
            bounce: None,
            bsp,
            bsp_path: bsp_path.to_path_buf(),
        })
    }

    /// The reference a setting is measured against.
    pub fn for_setting(&mut self, bounces: bool) -> Result<&Lighting, ReportError> {
        if !bounces {
            return Ok(&self.direct);
        }
        if self.bounce.is_none() {
            self.bounce = Some(reference(&self.bsp, &self.bsp_path, &self.faces, true)?);
        }
        Ok(&self.bounce.as_ref().expect("computed just above").0)
    }
}

fn reference(
    bsp: &Bsp,
    path: &Path,
    faces: &[usize],
    bounce: bool,
) -> Result<(Lighting, f64), ReportError> {
    let mut options = Options {
        quality: Quality::Reference,
        only_faces: Some(faces.to_vec()),
        ..Options::default()
    };
    options.overrides.bounce = bounce.then_some(1);
    let start = std::time::Instant::now();
    let raw = trace_lighting(bsp, &options).map_err(|source| ReportError::Light {
        path: path.to_path_buf(),
        source,
    })?;
    Ok((finish_lighting(&raw, 0), start.elapsed().as_secs_f64()))
}

/// A lit BSP's lightmaps against light's reference, in 8-bit grey levels.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct LightFigures {
    /// Luxels compared: those of the faces the reference lit.
    pub luxels: u64,
    /// Root mean square difference from the reference, in levels.
    pub rmse: f64,
    /// Largest difference from the reference, in levels.
    pub max: u8,
    /// Share of luxels more than 2 levels off (0 to 1).
    pub over_2_share: f64,
}

pub fn light_figures(lit_path: &Path, reference: &Lighting) -> Result<LightFigures, ReportError> {
    let lit = read_bsp(lit_path)?;
    let faces: Vec<usize> = reference.lightmaps.iter().map(|m| m.face).collect();
    let e = compare(&lightmaps_in(&lit, &faces), reference);
    Ok(LightFigures {
        luxels: e.luxels,
        rmse: e.rmse,
        max: e.max,
        over_2_share: e.over_2 as f64 / e.luxels.max(1) as f64,
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
