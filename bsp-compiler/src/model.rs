//! One model from its brushes to its trees and faces: the world and every brush entity go
//! through this on their own (in parallel).
//!
//! Two pipelines run side by side, each first marking with CSG the brush sides other brushes
//! bury ([`split_model`] parts the brushes, [`assemble`] joins the results). Hull 0,
//! the drawing tree: built, portalised (and, when detail split its structural leaves, portalised
//! again by clusters), its outside flooded from the world's point entities and filled, with the
//! space no entity reaches; a sealed world's tree is then built again, split by the sides that
//! face open space first (as ericw-tools does), so that planes facing the void only cut solid
//! space and collapse away, portalised and filled again; faces are made where leaf contents
//! change, merged, and cut where their lightmaps would grow too large. The two clip hulls: built,
//! and for a sealed world filled the same way (on copies when hull 0 has yet to tell whether the
//! world is sealed, kept when it is).

use crate::brush::Brush;
use crate::csg::mark_hidden_sides;
use crate::faces::{
    FaceStats, FaceTexInfo, MIN_SQUARENESS, ModelFace, cut_for_lightmaps, faces_from_portals,
    merge_faces, projection_squareness,
};
use crate::gather::ModelInput;
use crate::options::CompileOptions;
use crate::outside::{
    FillOutcome, Occupant, OnPlane, Reach, fill_from_void, fill_outside, fill_unreached,
    visible_sides,
};
use crate::planes::PlaneSet;
use crate::portals::{Portals, make_clip_hull_portals, make_cluster_portals, make_portals};
use crate::surface_tree::rebuild_from_surfaces;
use crate::tree::{Splitting, Tree, build_clip_hull_tree, build_tree, rebuild_tree_visible_first};
use crate::warnings::Warning;
use glam::DVec3;
use quake_formats::geom::Bounds;
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// Progress units a model's pipelines report per brush of [`ModelInput::work`]: one for its CSG,
/// one for its tree, one for filling and faces.
pub(crate) const MODEL_WORK_PER_BRUSH: usize = 3;

/// The phases [`ModelOutput::timings`] times, in its order.
pub(crate) const MODEL_PHASES: [&str; 6] = ["tree", "portals", "outside", "faces", "hulls", "csg"];

/// One model's trees and faces.
pub(crate) struct ModelOutput {
    /// How many times building hull 0's tree split a brush in two.
    pub splits: usize,
    /// Hull 0's portals.
    pub portals: usize,
    pub hulls: [Tree; 2],
    pub bounds: Bounds,
    pub fill: Option<FillOutcome>,
    pub face_stats: FaceStats,
    /// Seconds spent in each of [`MODEL_PHASES`].
    pub timings: [f64; 6],
}

/// A model's brushes, split between its two pipelines: hull 0 ([`DrawingJob`]) and the clip
/// hulls ([`ClipJob`]), which build side by side and are put together by [`assemble`].
pub(crate) fn split_model(m: ModelInput, options: &CompileOptions) -> (DrawingJob, ClipJob) {
    let shape = ModelShape {
        bounds: model_bounds(&m),
        // Only the world is flooded from the point entities.
        fills: m.entity == 0 && options.fill,
    };
    let sealed = Arc::new(OnceLock::new());
    (
        DrawingJob {
            shape,
            brushes: m.brushes,
            sealed: Arc::clone(&sealed),
        },
        ClipJob {
            shape,
            brushes: m.hull_brushes,
            sealed,
        },
    )
}

/// Whether hull 0 of a model that [`fills`] came out sealed: set by its pipeline once its first
/// flood is done (a second tree only replaces the first when sealed too), read by the clip
/// hulls' pipeline, which fills its hulls only for a sealed world.
///
/// [`fills`]: ModelShape::fills
type SealedVerdict = Arc<OnceLock<bool>>;

/// What both of a model's pipelines know of it.
#[derive(Debug, Clone, Copy)]
struct ModelShape {
    /// The model's bounds ([`model_bounds`]).
    bounds: Bounds,
    /// Its outside is flooded and filled (the world, unless `-nofill`).
    fills: bool,
}

/// A model's brushes for hull 0.
pub(crate) struct DrawingJob {
    shape: ModelShape,
    brushes: Vec<Brush>,
    sealed: SealedVerdict,
}

/// A model's grown brushes for hulls 1 and 2.
pub(crate) struct ClipJob {
    shape: ModelShape,
    brushes: [Vec<Brush>; 2],
    sealed: SealedVerdict,
}

/// Hull 0 of a model built, with its warnings and the seconds of its CSG.
pub(crate) struct Drawn {
    pub hull: DrawingHull,
    pub warnings: Vec<Warning>,
    shape: ModelShape,
    csg_time: f64,
}

/// The clip hulls of a model built, and for a sealed world filled, with the seconds of their CSG
/// and of the rest.
pub(crate) struct Clipped {
    hulls: ClipHulls,
    csg_time: f64,
    time: f64,
}

/// A model's clip hulls (1 and 2) as [`ModelBuild::clip_hulls`] leaves them.
enum ClipHulls {
    /// Built; the model is not filled, or hull 0 found the world open.
    Unfilled([Tree; 2]),
    /// Built and filled: hull 0 found the world sealed.
    Filled([Tree; 2]),
    /// Built, and filled on copies while hull 0 had yet to tell: the copies are kept when it is
    /// sealed.
    Both {
        unfilled: [Tree; 2],
        filled: [Tree; 2],
    },
}

/// What [`assemble`] takes of a model's hull 0 once it is written ([`Drawn::written`]): its
/// tree, portals and faces are gone.
pub(crate) struct Written {
    splits: usize,
    portals: usize,
    fill: Option<FillOutcome>,
    face_stats: FaceStats,
    times: [f64; 4],
    warnings: Vec<Warning>,
    shape: ModelShape,
    csg_time: f64,
}

impl Drawn {
    /// The model's bounds ([`model_bounds`]).
    pub(crate) fn bounds(&self) -> Bounds {
        self.shape.bounds
    }

    /// What stays once hull 0 is written: the tree, portals and faces are freed here, while
    /// the clip hulls still build.
    pub(crate) fn written(self) -> Written {
        let Drawn {
            hull,
            warnings,
            shape,
            csg_time,
        } = self;
        Written {
            splits: hull.tree.splits,
            portals: hull.portals.portals.len(),
            fill: hull.fill,
            face_stats: hull.face_stats,
            times: hull.times,
            warnings,
            shape,
            csg_time,
        }
    }
}

impl DrawingJob {
    /// CSG, then hull 0 built ([`ModelBuild::drawing_hull`]). `occupants` are the world's point
    /// entities (none for brush entities).
    pub(crate) fn build(
        self,
        planes: &PlaneSet,
        texinfos: &[FaceTexInfo],
        options: &CompileOptions,
        occupants: &[Occupant],
    ) -> Drawn {
        let t = Instant::now();
        let mut brushes = self.brushes;
        mark_hidden_sides(&mut brushes, planes);
        options.progress.advance(brushes.len());
        let csg_time = t.elapsed().as_secs_f64();
        let mut warnings = Vec::new();
        let hull = ModelBuild::new(planes, texinfos, options, occupants, self.shape).drawing_hull(
            brushes,
            &self.sealed,
            &mut warnings,
        );
        Drawn {
            hull,
            warnings,
            shape: self.shape,
            csg_time,
        }
    }
}

impl ClipJob {
    /// CSG, then the clip hulls built ([`ModelBuild::clip_hulls`]).
    pub(crate) fn build(
        self,
        planes: &PlaneSet,
        options: &CompileOptions,
        occupants: &[Occupant],
    ) -> Clipped {
        let t = Instant::now();
        let mut brushes = self.brushes;
        for list in &mut brushes {
            mark_hidden_sides(list, planes);
            options.progress.advance(list.len());
        }
        let csg_time = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let hulls =
            // The clip hulls make no faces: no texinfos.
            ModelBuild::new(planes, &[], options, occupants, self.shape)
                .clip_hulls(brushes, &self.sealed);
        Clipped {
            hulls,
            csg_time,
            time: t.elapsed().as_secs_f64(),
        }
    }
}

/// A model's output from its two pipelines; its warnings.
pub(crate) fn assemble(written: Written, clipped: Clipped) -> (ModelOutput, Vec<Warning>) {
    let Written {
        splits,
        portals,
        fill,
        face_stats,
        times,
        warnings,
        shape,
        csg_time,
    } = written;
    let sealed = matches!(fill, Some(FillOutcome::Sealed { .. }));
    let hulls = match clipped.hulls {
        ClipHulls::Unfilled(hulls) | ClipHulls::Filled(hulls) => hulls,
        ClipHulls::Both { filled, .. } if sealed => filled,
        ClipHulls::Both { unfilled, .. } => unfilled,
    };
    let mut timings = [0.0; 6];
    timings[..4].copy_from_slice(&times);
    timings[4] = clipped.time;
    timings[5] = csg_time + clipped.csg_time;
    (
        ModelOutput {
            splits,
            portals,
            hulls,
            bounds: shape.bounds,
            fill,
            face_stats,
            timings,
        },
        warnings,
    )
}

/// What each of a model's pipelines reads.
struct ModelBuild<'a> {
    planes: &'a PlaneSet,
    texinfos: &'a [FaceTexInfo],
    options: &'a CompileOptions,
    occupants: &'a [Occupant],
    splitting: Splitting,
    /// The model's bounds ([`model_bounds`]).
    bounds: Bounds,
    /// Its outside is flooded and filled (the world, unless `-nofill`).
    fills: bool,
}

impl<'a> ModelBuild<'a> {
    fn new(
        planes: &'a PlaneSet,
        texinfos: &'a [FaceTexInfo],
        options: &'a CompileOptions,
        occupants: &'a [Occupant],
        shape: ModelShape,
    ) -> Self {
        ModelBuild {
            planes,
            texinfos,
            options,
            occupants,
            splitting: Splitting {
                heuristic: options.heuristic,
                max_node_size: options.max_node_size,
            },
            bounds: shape.bounds,
            fills: shape.fills,
        }
    }
}

/// Hull 0 of a model, built: [`ModelOutput`]'s parts of it, and the seconds of its first four
/// [`MODEL_PHASES`].
pub(crate) struct DrawingHull {
    pub tree: Tree,
    pub portals: Portals,
    pub cluster_portals: Option<Portals>,
    fill: Option<FillOutcome>,
    pub faces: Vec<ModelFace>,
    face_stats: FaceStats,
    times: [f64; 4],
}

impl ModelBuild<'_> {
    /// Hull 0 from `brushes` to faces: built, portalised, and (when it [`fills`]) flooded and
    /// filled; a sealed world is then built again, split by the sides that face open space
    /// first (as ericw-tools does), so that planes facing the void only cut solid space and
    /// collapse away.
    ///
    /// [`fills`]: ModelBuild::fills
    fn drawing_hull(
        &self,
        brushes: Vec<Brush>,
        sealed: &OnceLock<bool>,
        warnings: &mut Vec<Warning>,
    ) -> DrawingHull {
        let (planes, options) = (self.planes, self.options);
        let mut times = [0.0; 4];
        let count = brushes.len();
        // Kept for the world's second tree, built once its outside is filled.
        let world_brushes = self.fills.then(|| brushes.clone());
        let t = Instant::now();
        let mut tree = build_tree(brushes, planes, self.splitting, true);
        options.progress.advance(count);
        times[0] = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let (mut portals, mut cluster_portals) = portalise(&tree, planes, &self.bounds);
        times[1] = t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut fill = self
            .fills
            .then(|| self.fill_world(&mut tree, &portals, cluster_portals.as_ref(), warnings));
        if let Some(outcome) = &fill {
            // Set once, here only.
            let _ = sealed.set(matches!(outcome, FillOutcome::Sealed { .. }));
        }
        times[2] = t.elapsed().as_secs_f64();
        if let (Some(FillOutcome::Sealed { .. }), Some(brushes)) = (&fill, world_brushes) {
            let t = Instant::now();
            let visible = visible_sides(&tree, &portals);
            let mut second = rebuild_tree_visible_first(brushes, planes, self.splitting, &visible);
            times[0] += t.elapsed().as_secs_f64();
            let t = Instant::now();
            let (second_portals, second_clusters) = portalise(&second, planes, &self.bounds);
            times[1] += t.elapsed().as_secs_f64();
            let t = Instant::now();
            // The same entities flood the same space: its warnings were given the first time.
            let mut repeated = Vec::new();
            let outcome = self.fill_world(
                &mut second,
                &second_portals,
                second_clusters.as_ref(),
                &mut repeated,
            );
            // Sealed again unless a sliver the new planes leave opens a crack: then keep the first.
            if matches!(outcome, FillOutcome::Sealed { .. }) {
                tree = second;
                portals = second_portals;
                cluster_portals = second_clusters;
                fill = Some(outcome);
            }
            times[2] += t.elapsed().as_secs_f64();
        }
        let t = Instant::now();
        let (faces, face_stats) =
            model_faces(&tree, &portals, planes, self.texinfos, options.subdivide);
        options.progress.advance(count);
        times[3] = t.elapsed().as_secs_f64();
        DrawingHull {
            tree,
            portals,
            cluster_portals,
            fill,
            faces,
            face_stats,
            times,
        }
    }

    /// Fill hull 0's outside, flooding over its cluster portals (its leaf portals when detail
    /// split nothing), then, once sealed and as the options ask, what no entity reaches.
    fn fill_world(
        &self,
        tree: &mut Tree,
        portals: &Portals,
        clusters: Option<&Portals>,
        warnings: &mut Vec<Warning>,
    ) -> FillOutcome {
        let (planes, occupants) = (self.planes, self.occupants);
        let flood = clusters.unwrap_or(portals);
        let mut outcome = fill_outside(tree, planes, flood, occupants, OnPlane::Sealing, warnings);
        if let (FillOutcome::Sealed { filled }, Some(reach)) =
            (&mut outcome, self.options.unreached_fill())
        {
            let units = match reach {
                Reach::Leaves => portals,
                Reach::Clusters => flood,
            };
            *filled += fill_unreached(tree, planes, units, occupants, reach);
        }
        outcome
    }

    /// The clip hulls' trees of `grown` (hulls 1 and 2), with their outsides filled when the
    /// model [`fills`] and hull 0 finds it `sealed`: a sealed world's clip hulls are sealed too
    /// (grown brushes only close gaps further), and filled each collapses into one solid leaf
    /// instead of many clip nodes. While hull 0 has yet to tell, they are filled on copies, which
    /// the caller keeps only when it is sealed; an open world's are not filled at all.
    ///
    /// [`fills`]: ModelBuild::fills
    fn clip_hulls(&self, grown: [Vec<Brush>; 2], sealed: &OnceLock<bool>) -> ClipHulls {
        let count = grown[0].len() + grown[1].len();
        let bounds = grown.each_ref().map(|list| {
            list.iter()
                .fold(Bounds::EMPTY, |acc, b| acc.union(&b.bounds))
        });
        let [h1, h2] = grown;
        let (planes, splitting) = (self.planes, self.splitting);
        let (a, b) = rayon::join(
            || build_clip_hull_tree(h1, planes, splitting),
            || build_clip_hull_tree(h2, planes, splitting),
        );
        let mut hulls = [a, b];
        let fill = |hulls: &mut [Tree; 2]| {
            let [f1, f2] = hulls;
            rayon::join(
                || self.fill_hull(f1, &bounds[0]),
                || self.fill_hull(f2, &bounds[1]),
            );
        };
        let out = match (self.fills, sealed.get()) {
            (false, _) | (true, Some(false)) => ClipHulls::Unfilled(hulls),
            (true, Some(true)) => {
                fill(&mut hulls);
                ClipHulls::Filled(hulls)
            }
            (true, None) => {
                let mut filled = hulls.clone();
                fill(&mut filled);
                ClipHulls::Both {
                    unfilled: hulls,
                    filled,
                }
            }
        };
        self.options.progress.advance(count);
        out
    }

    /// Fill the outside of a clip hull's tree, flooding from the world's point entities, then
    /// (as the options ask) what no entity reaches in this hull, and rebuild it from what is
    /// left. When no entity stands in this hull's open space, what the void reaches is filled
    /// all the same (hull 0 is sealed, so it is outside).
    fn fill_hull(&self, tree: &mut Tree, bounds: &Bounds) {
        if bounds.is_empty() {
            return;
        }
        let planes = self.planes;
        let portals = make_clip_hull_portals(tree, planes, bounds);
        // Entities near walls are inside the grown brushes; that is expected, not worth a
        // warning.
        let mut ignored = Vec::new();
        match fill_outside(
            tree,
            planes,
            &portals,
            self.occupants,
            OnPlane::Open,
            &mut ignored,
        ) {
            FillOutcome::Sealed { .. } => {
                // A clip hull has no detail: its clusters are its leaves.
                if self.options.unreached_fill().is_some() {
                    fill_unreached(tree, planes, &portals, self.occupants, Reach::Leaves);
                }
            }
            // Every entity is too near a wall for this hull's box: nothing tells the rooms
            // apart from what the void reaches, which is all the flood fills.
            FillOutcome::NoOccupants => {
                fill_from_void(tree, &portals);
            }
            FillOutcome::Leaked(_) => return,
        }
        *tree = rebuild_from_surfaces(tree, &portals, planes, self.splitting);
    }
}

/// The portals of `tree`'s leaves, and of its structural leaves when detail split some of them.
fn portalise(tree: &Tree, planes: &PlaneSet, bounds: &Bounds) -> (Portals, Option<Portals>) {
    let has_clusters = tree
        .nodes
        .iter()
        .any(|n| n.cluster.is_some() && !n.is_leaf());
    rayon::join(
        || make_portals(tree, planes, bounds),
        || has_clusters.then(|| make_cluster_portals(tree, planes, bounds)),
    )
}

/// The bounds engines size a model by (a door's travel, its trigger field): its map brushes,
/// clip brushes included, not the grown ones; a unit box around the origin for an empty model.
/// The file stores them a unit inside on every side (see `emit`), and the portals' outside box
/// is a margin outside them.
fn model_bounds(m: &ModelInput) -> Bounds {
    let bounds = m
        .brushes
        .iter()
        .fold(m.clip_bounds, |acc, b| acc.union(&b.bounds));
    if bounds.is_empty() {
        Bounds {
            mins: DVec3::new(-1.0, -1.0, -1.0),
            maxs: DVec3::new(1.0, 1.0, 1.0),
        }
    } else {
        bounds
    }
}

/// The faces of hull 0: made on the portals where leaf contents change, merged, and cut for
/// their lightmaps (a face whose texture meets it edge-on waits until it has a projection of its
/// own: see `square_up_projections` in the compile).
fn model_faces(
    tree: &Tree,
    portals: &Portals,
    planes: &PlaneSet,
    texinfos: &[FaceTexInfo],
    subdivide: f64,
) -> (Vec<ModelFace>, FaceStats) {
    let mut stats = FaceStats::default();
    let raw = faces_from_portals(tree, portals, planes, texinfos, &mut stats);
    let merged = merge_faces(raw, |f| *planes.get(f.plane));
    stats.after_merge = merged.len();
    let mut faces = Vec::with_capacity(merged.len());
    for f in merged {
        let info = &texinfos[f.texinfo as usize];
        if projection_squareness(&info.vecs, f.normal(planes)) < MIN_SQUARENESS {
            faces.push(f);
        } else {
            cut_for_lightmaps(f, info, subdivide, &mut faces);
        }
    }
    (faces, stats)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brush::tests::box_brush;
    use crate::hulls::{HULL_BOXES, bevelled_planes, grown_planes};
    use quake_formats::bsp::contents;

    /// The six walls of a closed room 512 units wide, grown for each clip hull.
    fn grown_room(planes: &mut PlaneSet) -> [Vec<Brush>; 2] {
        let (lo, hi) = (-256.0, 256.0);
        let mut walls = Vec::new();
        for axis in 0..3 {
            for (a, b) in [(lo - 16.0, lo), (hi, hi + 16.0)] {
                let (mut mins, mut maxs) = (DVec3::splat(lo - 16.0), DVec3::splat(hi + 16.0));
                mins[axis] = a;
                maxs[axis] = b;
                walls.push(box_brush(planes, mins, maxs, contents::SOLID));
            }
        }
        HULL_BOXES.map(|(mins, maxs)| {
            walls
                .iter()
                .map(|w| {
                    let faces = grown_planes(&bevelled_planes(w, planes), mins, maxs);
                    Brush::from_planes(&faces, planes, contents::SOLID, w.source).expect("grown")
                })
                .collect()
        })
    }

    /// Whether hull 0 has told the clip hulls' pipeline if the world is sealed or not, the trees
    /// it keeps are the ones it keeps when it fills copies before knowing.
    #[test]
    fn clip_hulls_are_the_same_whenever_hull_0_tells_whether_the_world_is_sealed() {
        let mut planes = PlaneSet::new();
        let mut grown = grown_room(&mut planes);
        for list in &mut grown {
            mark_hidden_sides(list, &planes);
        }
        let options = CompileOptions::default();
        let occupants = [Occupant {
            entity: 1,
            classname: "info_player_start".to_string(),
            origin: DVec3::new(10.0, 20.0, 30.0),
            line: 1,
        }];
        let shape = ModelShape {
            bounds: Bounds {
                mins: DVec3::splat(-272.0),
                maxs: DVec3::splat(272.0),
            },
            fills: true,
        };
        let build = ModelBuild::new(&planes, &[], &options, &occupants, shape);
        let told = |sealed: Option<bool>| {
            let verdict = OnceLock::new();
            if let Some(sealed) = sealed {
                let _ = verdict.set(sealed);
            }
            build.clip_hulls(grown.clone(), &verdict)
        };
        let ClipHulls::Both { unfilled, filled } = told(None) else {
            panic!("filled on copies while hull 0 has not told");
        };
        let ClipHulls::Filled(sealed) = told(Some(true)) else {
            panic!("filled in place for a sealed world");
        };
        let ClipHulls::Unfilled(open) = told(Some(false)) else {
            panic!("not filled for an open world");
        };
        assert_eq!(sealed, filled);
        assert_eq!(open, unfilled);
        // Filling did something: the void around the room is solid.
        assert_ne!(filled, unfilled);
    }
}
