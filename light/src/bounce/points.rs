//! Bounced light from points, as ericw-tools gives it (its `-emissivequality low` and
//! `medium`, low its default): each reflecting face sends what it reflects from one point a
//! unit in front of its middle (and, at medium, from each of its corners too, the face's light
//! shared among them), as a point light with the bounce kernel.
//!
//! A face's light is the mean over its luxels of what it reflects, `ρ E` (occluded luxels count
//! as dark). Its strongest channel `I` times its area is the point's intensity, and its colour
//! is the light over `I` when `I` exceeds 1 (else the light itself: ericw-tools' rule, which
//! makes faces dimmer than one light unit dimmer still). A receiving luxel at `p`, `d` from a
//! point, takes `kernel · intensity · cos θe · cos θr / max(d, 128)²` of that colour, where `θe`
//! is the angle off the emitting face's normal and `θr` off the receiver's (a liquid's surface
//! takes it from both sides, without `cos θr`), if nothing blocks the segment between them.
//!
//! Next to [`super::Field`]'s gather, which integrates over the reflecting surfaces, this is
//! coarse: a face's light leaves from one point, so a face next to a large bright wall takes
//! the wall's light as if it were all at the wall's middle. It is what maps lit by
//! ericw-tools were tuned with. Its cost grows with receivers times emitters in sight, so it
//! culls as ericw-tools does: emitters whose faces lie in a leaf outside the receiving face's
//! PVS, behind it, or too far to bring more than [`GATE`]; and traces segments coarse to fine
//! over a face's luxels (see [`see`]).

use glam::{DVec3, Vec3};
use quake_formats::geom::{Plane, Split, Winding, polygon_area};

use super::{
    BounceCounts, Field, HOTSPOT_CLAMP, Receivers, StyleLight, StyleLuxels, add_style_light,
};
use crate::bits::ones;
use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::scene::TraceScene;
use crate::visibility::{Visibility, bit};

/// Contributions below this many light units, in every channel, count as none (ericw-tools'
/// gate for bounced light).
const GATE: f64 = 0.01;

/// An emitter that brings no luxel of a face more than this many light units is seen or not
/// by the whole face at once: a segment to one luxel, drawn in proportion to what each takes
/// ([`weighted_pick`]), decides. Where its shadow crosses the face, luxels are off by at most
/// this much light, and the face's light is right on average.
const WEAK: f64 = 1.0;

/// Points nearer than this (units) to an emitter count as this near (ericw-tools' floor).
const MIN_DISTANCE: f32 = 0.01;

/// Faces smaller than this (square units) give off no bounced light.
const MIN_AREA: f64 = 1.0;

/// Corners closer than this to a straight line through their neighbours (the cosine between
/// the two edges) are not corners of the face's outline: T-junction points.
const STRAIGHT: f64 = 0.999;

/// A piece of a face being diced that reaches less than this (units) past a cutting plane is
/// not cut there ([`dice`]), as ericw-tools dices.
const DICE_OVERLAP: f64 = 1.0;

/// Pieces along a face's longest side at most when it is diced ([`Emission::Diced`]): a map's
/// `_bouncelightsubdivision 1` would otherwise cut a large floor into millions of points.
const DICED_ACROSS: f64 = 64.0;

/// How many points a reflecting face sends its light from.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Emission {
    /// One, in front of its middle.
    Middle,
    /// Its middle and each corner.
    MiddleAndCorners,
    /// The middle of each piece of the face diced by planes across the axes, this many units
    /// apart (ericw-tools' `-emissivequality high`, `_bouncelightsubdivision`).
    Diced(f64),
}

/// One point a reflecting face sends light from.
#[derive(Debug, Clone)]
pub struct PointEmitter {
    face: usize,
    point: DVec3,
    normal: DVec3,
    /// Per style: the colour and the intensity.
    styles: Vec<(u8, [f32; 3], f64)>,
    /// Its share of its face's light (1 over the face's points).
    share: f64,
    /// Its intensity in its brightest style (of `styles`, which nothing changes after).
    brightest: f64,
}

/// The point emitters of one pass, and where they stand.
pub struct PointField<'a> {
    emitters: Vec<PointEmitter>,
    /// The emitters' points, normals and intensities column by column, for [`may_light`].
    columns: EmitterColumns,
    /// The emitters [`GROUP`] at a time, from the first.
    groups: Vec<EmitterGroup>,
    /// Per emitter, the one leaf that holds its face ([`NO_LEAF`]: none, or several).
    leaf: Vec<u32>,
    faces: &'a [FaceGeom],
    vis: &'a Visibility,
    kernel: f64,
}

impl<'a> PointField<'a> {
    /// The points `field`'s reflecting faces send their light from.
    pub fn new(field: &Field<'a>, vis: &'a Visibility, emission: Emission) -> PointField<'a> {
        let emitters = point_emitters(field, emission);
        let leaf = emitters
            .iter()
            .map(|e| match vis.face_leafs(e.face) {
                &[l] => l,
                _ => NO_LEAF,
            })
            .collect();
        let groups = emitters
            .chunks(GROUP)
            .map(|group| EmitterGroup::new(group, |f| vis.face_leafs(f)))
            .collect();
        PointField {
            columns: EmitterColumns::new(&emitters),
            groups,
            leaf,
            emitters,
            faces: field.faces,
            vis,
            kernel: field.kernel,
        }
    }

    /// What vis data says of the emitters face `face` may see.
    fn sight(&self, face: usize) -> Sight {
        // A face no leaf holds sees nothing (ericw-tools' empty PVS for it).
        if self.vis.unheld(face) {
            return Sight::Nothing;
        }
        match self.vis.pvs_of(self.vis.face_leafs(face)) {
            Some(pvs) => Sight::Pvs(pvs),
            None => Sight::Everything,
        }
    }

    /// Whether emitter `k` is in `sight`.
    fn in_sight(&self, k: usize, sight: &Sight) -> bool {
        match sight {
            Sight::Nothing => false,
            Sight::Everything => true,
            Sight::Pvs(pvs) => match self.leaf[k] {
                NO_LEAF => self
                    .vis
                    .in_pvs(pvs, self.vis.face_leafs(self.emitters[k].face)),
                // One leaf: in sight when it is in the PVS (liquid or not).
                leaf => bit(pvs, leaf),
            },
        }
    }

    /// The light the emitters send each luxel of `r`, per style.
    pub fn gather_face(
        &self,
        scene: &TraceScene,
        r: &Receivers,
        counts: &mut BounceCounts,
    ) -> StyleLuxels {
        let n = r.points.len();
        let plane = self.faces[r.face].plane;
        let points: Vec<DVec3> = r.points.iter().map(|&p| Vec3::from(p).as_dvec3()).collect();
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &p in &points {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        // The emitters that may light some luxel, and each luxel's weight from each, a batch
        // at a time.
        let mut out = StyleColumns::default();
        let mut rows = WeightRows::new(n);
        let at = Luxels::new(&r.points, &r.normals, rows.stride);
        // One normal for every luxel (a flat one-sided face): the receiving cosine is bounded
        // by the emitter's height over the luxels too.
        let flat_normal = r
            .normals
            .first()
            .filter(|&&first| !r.two_sided && r.normals.iter().all(|&m| m == first))
            .map(|&m| Vec3::from(m).as_dvec3());
        let sight = self.sight(r.face);
        let cull = Cull {
            plane,
            two_sided: r.two_sided,
            lo,
            hi,
            kernel: self.kernel,
        };
        // The emitters a group at a time: the cheap tests on all of them at once, then sight.
        let mut candidates = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            if !group.may_light(&cull) || !group.in_sight(&sight) {
                continue;
            }
            let first = g * GROUP;
            for k in ones(may_light(&self.columns, first, &cull)).map(|k| first + k) {
                if self.emitters[k].face != r.face && self.in_sight(k, &sight) {
                    candidates.push(k);
                }
            }
        }
        for k in candidates {
            let e = &self.emitters[k];
            let max_total = e.max_intensity();
            if flat_normal
                .is_some_and(|n_r| under_gate(e, n_r, (lo, hi), self.kernel * max_total / GATE))
            {
                continue;
            }
            let gate = (GATE / max_total) as f32;
            rows.push(e, &at, self.kernel as f32, gate, r.two_sided);
            if rows.is_full() {
                light_batch(scene, r, &points, &rows, &mut out, counts);
                rows.clear();
            }
        }
        light_batch(scene, r, &points, &rows, &mut out, counts);
        out.into_luxels()
    }
}

impl PointField<'_> {
    /// The light the emitters send a point in the open (a brush model's middle, for its
    /// estimate of its light), per style, as ericw-tools' light grid takes it: no surface there,
    /// so each emitter's `cos θr` is that of the side of a cube facing it most, the largest
    /// coordinate of the unit direction. Emitters whose faces are not wholly in the PVS of the
    /// point's leaf (`leaf`) are culled, as for a face.
    pub fn light_at(
        &self,
        scene: &TraceScene,
        leaf: Option<u32>,
        p: DVec3,
        counts: &mut BounceCounts,
    ) -> StyleLight {
        let pvs = leaf.and_then(|l| self.vis.pvs_of(&[l]));
        let mut out = StyleLight::new();
        let mut packet = RayPacket16::new();
        for e in &self.emitters {
            if pvs
                .as_ref()
                .is_some_and(|pvs| !self.vis.sees_all(pvs, self.vis.face_leafs(e.face)))
            {
                continue;
            }
            let t = p - e.point;
            let d2 = t
                .length_squared()
                .max(f64::from(MIN_DISTANCE * MIN_DISTANCE));
            let d = d2.sqrt();
            let along_e = e.normal.dot(t).max(0.0) / d;
            let facing_side = t.abs().max_element() / d;
            let weight =
                self.kernel * along_e * facing_side / d2.max(HOTSPOT_CLAMP * HOTSPOT_CLAMP);
            let passes = |&&(_, color, total): &&(u8, [f32; 3], f64)| {
                f64::from(color[0].max(color[1]).max(color[2])) * weight * total >= GATE
            };
            if !e.styles.iter().any(|s| passes(&s)) {
                continue;
            }
            // One segment a time: a lone lane is traced as the faces' segments are.
            packet.clear();
            let end = (d as f32 - crate::trace::RAY_START).max(0.0);
            let (from, dir) = (e.point.as_vec3().to_array(), (t / d).as_vec3().to_array());
            packet.set(0, from, dir, crate::trace::RAY_START, end);
            counts.rays += 1;
            if scene.occluded16(&mut packet, 0) & 1 != 0 {
                continue;
            }
            for &(style, color, total) in e.styles.iter().filter(passes) {
                let w = weight * total;
                add_style_light(&mut out, style, color.map(|c| (w * f64::from(c)) as f32));
            }
        }
        out
    }
}

/// [`PointField`]'s mark of an emitter whose face is not in exactly one leaf.
const NO_LEAF: u32 = u32::MAX;

/// The emitters vis data lets a face see.
enum Sight {
    /// None: the face is in no leaf.
    Nothing,
    /// Those whose faces are in this PVS ([`Visibility::in_pvs`]).
    Pvs(Vec<u8>),
    /// All: vis data cannot tell.
    Everything,
}

/// A receiving face, for [`may_light`]: its plane, whether it takes light from both sides, its
/// luxels' box, and the bounce kernel.
struct Cull {
    plane: Plane,
    two_sided: bool,
    lo: DVec3,
    hi: DVec3,
    kernel: f64,
}

/// Emitters' points, normals and brightest intensities, coordinate by coordinate.
struct EmitterColumns {
    at: [Vec<f64>; 3],
    normal: [Vec<f64>; 3],
    brightest: Vec<f64>,
}

impl EmitterColumns {
    fn new(emitters: &[PointEmitter]) -> EmitterColumns {
        let column = |f: &dyn Fn(&PointEmitter) -> f64| emitters.iter().map(f).collect();
        EmitterColumns {
            at: [
                column(&|e| e.point.x),
                column(&|e| e.point.y),
                column(&|e| e.point.z),
            ],
            normal: [
                column(&|e| e.normal.x),
                column(&|e| e.normal.y),
                column(&|e| e.normal.z),
            ],
            brightest: column(&|e| e.brightest),
        }
    }
}

/// Emitters are culled this many at a time (a bit each of a `u64`): consecutive emitters are
/// on faces the compiler wrote one after another, close together, so a group's bounds often
/// rule all of them out at once.
const GROUP: usize = 64;

/// Relative slack on [`EmitterGroup::may_light`]'s bounds for their rounding (the emitters' own
/// tests round a little differently).
const GROUP_ROUNDING: f64 = 1e-6;

/// What a face's cull asks of a [`GROUP`] of emitters at once.
struct EmitterGroup {
    /// The box around their points.
    lo: DVec3,
    hi: DVec3,
    /// Their largest intensity.
    brightest: f64,
    /// The leaves that hold their faces (`None`: one face is in no leaf, in sight of all).
    leafs: Option<Vec<u32>>,
}

impl EmitterGroup {
    /// The group of `group`, whose faces `face_leafs` holds.
    fn new<'v>(group: &[PointEmitter], face_leafs: impl Fn(usize) -> &'v [u32]) -> EmitterGroup {
        let (mut lo, mut hi, mut brightest) = (DVec3::INFINITY, DVec3::NEG_INFINITY, 0.0f64);
        let mut leafs = Some(Vec::new());
        for e in group {
            (lo, hi, brightest) = (lo.min(e.point), hi.max(e.point), brightest.max(e.brightest));
            let of_face = face_leafs(e.face);
            match &mut leafs {
                Some(all) if !of_face.is_empty() => all.extend_from_slice(of_face),
                _ => leafs = None,
            }
        }
        if let Some(all) = &mut leafs {
            all.sort_unstable();
            all.dedup();
        }
        EmitterGroup {
            lo,
            hi,
            brightest,
            leafs,
        }
    }

    /// False when none of the group can pass [`may_light`]: every point of its box is behind a
    /// one-sided face, or its brightest is too dim for the gate at the box's distance from the
    /// face's luxels.
    fn may_light(&self, cull: &Cull) -> bool {
        let normal = cull.plane.normal;
        // The box's corner farthest in front of the plane.
        let front = DVec3::select(normal.cmpgt(DVec3::ZERO), self.hi, self.lo);
        let slack = GROUP_ROUNDING * (1.0 + front.abs().max_element() + cull.plane.dist.abs());
        if !cull.two_sided && cull.plane.distance(front) < -slack {
            return false;
        }
        // The gaps between the two boxes along each axis (0 where they overlap).
        let gap = (cull.lo - self.hi).max(self.lo - cull.hi).max(DVec3::ZERO);
        let clamp = HOTSPOT_CLAMP * HOTSPOT_CLAMP;
        let bound = cull.kernel * self.brightest / gap.length_squared().max(clamp);
        bound * (1.0 + GROUP_ROUNDING) >= GATE
    }

    /// False when `sight` holds none of the group ([`PointField::in_sight`] wants one of an
    /// emitter's leaves in the PVS).
    fn in_sight(&self, sight: &Sight) -> bool {
        match (sight, &self.leafs) {
            (Sight::Nothing, _) => false,
            (Sight::Pvs(pvs), Some(leafs)) => leafs.iter().any(|&l| bit(pvs, l)),
            _ => true,
        }
    }
}

/// Of the (up to) [`GROUP`] emitters from `first`, bit `i` set for each that may light a luxel of
/// `cull`'s face: in front of it (unless it is two-sided), facing a corner of its luxels' box,
/// and near enough to the box for its brightest intensity to pass the [`GATE`]. Branch-free
/// over the columns, so that it runs in vectors.
fn may_light(columns: &EmitterColumns, first: usize, cull: &Cull) -> u64 {
    crate::simd::widest(
        #[inline(always)]
        || may_light_any(columns, first, cull),
    )
}

/// [`may_light`] for whatever the build targets.
#[inline(always)]
fn may_light_any(columns: &EmitterColumns, first: usize, cull: &Cull) -> u64 {
    let end = (first + GROUP).min(columns.brightest.len());
    let [px, py, pz] = columns.at.each_ref().map(|c| &c[first..end]);
    let [ux, uy, uz] = columns.normal.each_ref().map(|c| &c[first..end]);
    let brightest = &columns.brightest[first..end];
    let n = brightest.len();
    let (px, py, pz, ux, uy, uz) = (&px[..n], &py[..n], &pz[..n], &ux[..n], &uy[..n], &uz[..n]);
    let (normal, dist) = (cull.plane.normal, cull.plane.dist);
    let (lo, hi) = (cull.lo, cull.hi);
    let clamp = HOTSPOT_CLAMP * HOTSPOT_CLAMP;
    // Comparisons and selects rather than `f64::max`, `||` and `if`: the same values here (no
    // NaN), and they run in vectors.
    let pick = |c: bool, a: f64, b: f64| if c { a } else { b };
    let inside = |v: f64, lo: f64, hi: f64| {
        let v = pick(v > lo, v, lo);
        pick(v < hi, v, hi)
    };
    let mut keep = [0u8; GROUP];
    for (i, slot) in keep[..n].iter_mut().enumerate() {
        let (x, y, z) = (px[i], py[i], pz[i]);
        // The sums as `Plane::distance` and glam's dot products make them.
        let in_front = normal.x * x + normal.y * y + normal.z * z - dist > 0.0;
        // The corner of the box farthest along the emitter's normal.
        let (fx, fy, fz) = (
            pick(ux[i] > 0.0, hi.x, lo.x),
            pick(uy[i] > 0.0, hi.y, lo.y),
            pick(uz[i] > 0.0, hi.z, lo.z),
        );
        let facing = ux[i] * (fx - x) + uy[i] * (fy - y) + uz[i] * (fz - z) >= 0.0;
        let (dx, dy, dz) = (
            inside(x, lo.x, hi.x) - x,
            inside(y, lo.y, hi.y) - y,
            inside(z, lo.z, hi.z) - z,
        );
        let nearest = dx * dx + dy * dy + dz * dz;
        let bright = cull.kernel * brightest[i] / pick(nearest > clamp, nearest, clamp) >= GATE;
        *slot = u8::from((in_front | cull.two_sided) & facing & bright);
    }
    let mut bits = 0u64;
    for (byte, group) in keep.chunks_exact(8).enumerate() {
        let packed = group
            .iter()
            .enumerate()
            .fold(0u64, |b, (i, &k)| b | u64::from(k) << i);
        bits |= packed << (byte * 8);
    }
    bits
}

/// Slack on the bounds of [`under_gate`], in units, for the single precision [`weigh`] works
/// in (coordinates within a few thousand units: their rounding is well under this).
const BOUND_SLACK: f64 = 0.01;

/// Relative slack on [`under_gate`]'s bound for the rounding of [`weigh`]'s single-precision
/// products and quotient (each off by a few parts in ten million).
const BOUND_ROUNDING: f64 = 1e-3;

/// Whether every luxel in the box `(lo, hi)` of a flat one-sided face with normal `n_r` takes
/// from `e` a weight [`weigh`] sets to zero, `scale` being the kernel times the emitter's
/// intensity over the gate: `cos θe · d` is at most the largest of `n_e · (c − e)` over the
/// box's corners `c`, `cos θr · d` at most that of `−n_r · (c − e)` (both linear, so largest
/// at a corner), and `d` at least the box's distance, each widened by [`BOUND_SLACK`] and the
/// product by [`BOUND_ROUNDING`].
fn under_gate(e: &PointEmitter, n_r: DVec3, (lo, hi): (DVec3, DVec3), scale: f64) -> bool {
    let most_along = |n: DVec3| {
        let (a, b) = (n * (lo - e.point), n * (hi - e.point));
        a.max(b).element_sum() + BOUND_SLACK
    };
    let (along_e, along_r) = (most_along(e.normal), most_along(-n_r));
    if along_e <= 0.0 || along_r <= 0.0 {
        return true;
    }
    let near = (e.point.clamp(lo, hi).distance(e.point) - BOUND_SLACK).max(f64::from(MIN_DISTANCE));
    let d2 = near * near;
    let clamp = HOTSPOT_CLAMP * HOTSPOT_CLAMP;
    scale * along_e * along_r / (d2 * d2.max(clamp)) * (1.0 + BOUND_ROUNDING) < 1.0
}

/// A face's luxels, coordinate by coordinate (so that weighing them vectorises), each column
/// padded with zeros to a given length.
struct Luxels {
    at: [Vec<f32>; 3],
    normal: [Vec<f32>; 3],
}

impl Luxels {
    fn new(points: &[[f32; 3]], normals: &[[f32; 3]], padded: usize) -> Luxels {
        let axis = |v: &[[f32; 3]], k: usize| {
            let mut column: Vec<f32> = v.iter().map(|p| p[k]).collect();
            column.resize(padded.max(v.len()), 0.0);
            column
        };
        Luxels {
            at: [0, 1, 2].map(|k| axis(points, k)),
            normal: [0, 1, 2].map(|k| axis(normals, k)),
        }
    }
}

/// Rows of [`WeightRows`] are padded to a multiple of this many weights: a face's luxels are
/// then weighed in whole vectors of eight, with no one-at-a-time tail for the last few (most
/// faces have a few dozen luxels, and a few hundred thousand emitters to weigh them for).
const ROW_LANES: usize = 8;

/// The emitters that light a face's luxels, with each one's weight at each luxel (a row per
/// emitter, [`WeightRows::stride`] long: the luxels' weights, then zeros), and the largest of
/// its weights and their sum, worked out as it is weighed.
struct WeightRows<'e> {
    luxels: usize,
    stride: usize,
    emitters: Vec<WeighedEmitter<'e>>,
    weights: Vec<f32>,
}

/// An emitter of a [`WeightRows`], with [`largest_and_total`] of its weights.
struct WeighedEmitter<'e> {
    emitter: &'e PointEmitter,
    largest: f32,
    total: f32,
}

impl<'e> WeightRows<'e> {
    /// No rows yet, for a face of `luxels` luxels.
    fn new(luxels: usize) -> WeightRows<'e> {
        let stride = luxels.next_multiple_of(ROW_LANES);
        WeightRows {
            luxels,
            stride,
            emitters: Vec::new(),
            weights: Vec::with_capacity(BATCH + stride),
        }
    }

    /// Weighs the luxels `at` for emitter `e` ([`weigh`]) and keeps its row, unless every weight
    /// is 0.
    fn push(&mut self, e: &'e PointEmitter, at: &Luxels, kernel: f32, gate: f32, two_sided: bool) {
        let start = self.weights.len();
        self.weights.resize(start + self.stride, 0.0);
        let row = &mut self.weights[start..];
        weigh(e, at, kernel, gate, two_sided, row);
        row[self.luxels..].fill(0.0);
        // Weights are 0 or at least the gate: the largest is 0 only when all are.
        let (largest, total) = largest_and_total(&row[..self.luxels]);
        if largest == 0.0 {
            self.weights.truncate(start);
            return;
        }
        self.emitters.push(WeighedEmitter {
            emitter: e,
            largest,
            total,
        });
    }

    /// The weights of row `k`'s emitter at the luxels.
    fn row(&self, k: usize) -> &[f32] {
        &self.weights[k * self.stride..][..self.luxels]
    }

    /// Whether it holds a batch's worth of weights ([`BATCH`]).
    fn is_full(&self) -> bool {
        self.weights.len() >= BATCH
    }

    fn clear(&mut self) {
        self.emitters.clear();
        self.weights.clear();
    }
}

/// Each luxel's weight from emitter `e`: `kernel · cos θe · cos θr / max(d, 128)²` (`cos θr`
/// taken as 1 for a two-sided face), 0 where that is under `gate`.
fn weigh(
    e: &PointEmitter,
    luxels: &Luxels,
    kernel: f32,
    gate: f32,
    two_sided: bool,
    out: &mut [f32],
) {
    crate::simd::widest(
        #[inline(always)]
        || weigh_any(e, luxels, kernel, gate, two_sided, out),
    );
}

/// [`weigh`] for whatever the build targets.
#[inline(always)]
fn weigh_any(
    e: &PointEmitter,
    luxels: &Luxels,
    kernel: f32,
    gate: f32,
    two_sided: bool,
    out: &mut [f32],
) {
    let [ex, ey, ez] = e.point.as_vec3().to_array();
    let [ux, uy, uz] = e.normal.as_vec3().to_array();
    let clamp = (HOTSPOT_CLAMP * HOTSPOT_CLAMP) as f32;
    let [px, py, pz] = &luxels.at;
    let [nx, ny, nz] = &luxels.normal;
    let n = out.len();
    // cos θe · cos θr / max(d, 128)², without a square root for one-sided faces; one loop per
    // kind of face, each free of branches and of index checks (zipped columns), so that it
    // runs in whole vectors with a tail only for a row that is not a multiple of eight long.
    let at = px[..n].iter().zip(&py[..n]).zip(&pz[..n]);
    let along = |((x, y), z): ((&f32, &f32), &f32)| (x - ex, y - ey, z - ez);
    let finish = |w: f32| if w < gate { 0.0 } else { w };
    if two_sided {
        for (slot, p) in out.iter_mut().zip(at) {
            let (tx, ty, tz) = along(p);
            let d2 = (tx * tx + ty * ty + tz * tz).max(MIN_DISTANCE * MIN_DISTANCE);
            let along_e = (ux * tx + uy * ty + uz * tz).max(0.0);
            *slot = finish(kernel * along_e * d2.sqrt() / (d2 * d2.max(clamp)));
        }
    } else {
        let normals = nx[..n].iter().zip(&ny[..n]).zip(&nz[..n]);
        for ((slot, p), ((mx, my), mz)) in out.iter_mut().zip(at).zip(normals) {
            let (tx, ty, tz) = along(p);
            let d2 = (tx * tx + ty * ty + tz * tz).max(MIN_DISTANCE * MIN_DISTANCE);
            let along_e = (ux * tx + uy * ty + uz * tz).max(0.0);
            let along_r = (-(mx * tx + my * ty + mz * tz)).max(0.0);
            *slot = finish(kernel * along_e * along_r / (d2 * d2.max(clamp)));
        }
    }
}

/// The largest of `weights` (none is a NaN, none negative), 0 for none, and their sum: lane by
/// lane over blocks of eight, so that it runs in vectors; a maximum is exact whatever the
/// order.
fn largest_and_total(weights: &[f32]) -> (f32, f32) {
    let (mut most, mut sums) = ([0.0f32; 8], [0.0f32; 8]);
    let mut blocks = weights.chunks_exact(8);
    for block in &mut blocks {
        for ((m, s), &w) in most.iter_mut().zip(&mut sums).zip(block) {
            *m = if w > *m { w } else { *m };
            *s += w;
        }
    }
    let rest = blocks.remainder();
    let largest = rest
        .iter()
        .chain(&most)
        .fold(0.0f32, |m, &w| if w > m { w } else { m });
    (largest, rest.iter().chain(&sums).sum())
}

/// The luxel whose segment decides a weak emitter's visibility (see [`WEAK`]): drawn by `key`
/// with a chance in proportion to its weight (`total` the weights' sum), so that over the weak
/// emitters a face sees, the light let through is on average what a segment to every luxel
/// would let through. (The luxel an emitter lights most is where the face comes nearest it,
/// often against the geometry the emitter's own face meets, and is blocked more often than
/// the face's luxels are: deciding by it darkened bounce, the more so in later passes, where
/// most emitters are weak.) The first luxel when none has any weight.
fn weighted_pick(weights: &[f32], total: f32, key: u64) -> usize {
    if total <= 0.0 {
        return 0;
    }
    let target = (super::unit(key) * f64::from(total)) as f32;
    let mut sum = 0.0f32;
    let mut blocks = weights.chunks_exact(8);
    let mut start = 0;
    for block in &mut blocks {
        let s: f32 = block.iter().sum();
        if sum + s > target {
            break;
        }
        sum += s;
        start += 8;
    }
    for (i, &w) in weights.iter().enumerate().skip(start) {
        sum += w;
        if sum > target {
            return i;
        }
    }
    // Rounding left the target past the sum: the last luxel with weight.
    weights.iter().rposition(|&w| w > 0.0).unwrap_or(0)
}

/// Weights held at once while lighting a face: emitters times luxels.
const BATCH: usize = 1 << 15;

impl PointEmitter {
    /// The key of its draws for the face `receiver`: of the two faces and where the point is
    /// (not of threads or the order faces are lit in).
    fn key(&self, receiver: usize) -> u64 {
        let [x, y, z] = self.point.to_array().map(f64::to_bits);
        super::point_key(
            receiver,
            self.face,
            (x ^ y.rotate_left(21) ^ z.rotate_left(42)) as usize,
        )
    }

    /// Its intensity in its brightest style.
    fn max_intensity(&self) -> f64 {
        self.brightest
    }
}

/// A face's light per style, channel by channel (so that adding to it runs in vectors).
#[derive(Default)]
struct StyleColumns(Vec<(u8, [Vec<f32>; 3])>);

impl StyleColumns {
    /// The channels of `style`'s light at `n` luxels, made dark if it has none yet.
    fn style(&mut self, style: u8, n: usize) -> &mut [Vec<f32>; 3] {
        crate::styles::entry(&mut self.0, style, || std::array::from_fn(|_| vec![0.0; n]))
    }

    /// The light per style, luxel by luxel.
    fn into_luxels(self) -> StyleLuxels {
        let luxel = |[r, g, b]: &[Vec<f32>; 3], i: usize| [r[i], g[i], b[i]];
        self.0
            .into_iter()
            .map(|(style, c)| (style, (0..c[0].len()).map(|i| luxel(&c, i)).collect()))
            .collect()
    }
}

/// Adds to `light` the light of an emitter of colour `color` and intensity `total` at each
/// luxel whose segment is lit and which it brings at least the gate, at `weights`.
fn add_lit(light: &mut [Vec<f32>; 3], weights: &[f32], lit: &[State], color: [f32; 3], total: f64) {
    crate::simd::widest(
        #[inline(always)]
        || add_lit_any(light, weights, lit, color, total),
    );
}

/// [`add_lit`] for whatever the build targets.
#[inline(always)]
fn add_lit_any(
    [r, g, b]: &mut [Vec<f32>; 3],
    weights: &[f32],
    lit: &[State],
    color: [f32; 3],
    total: f64,
) {
    let strongest = f64::from(color[0].max(color[1]).max(color[2]));
    let [cr, cg, cb] = color.map(f64::from);
    let n = weights.len();
    let luxels = r[..n].iter_mut().zip(&mut g[..n]).zip(&mut b[..n]);
    // Without branches: a luxel that takes nothing adds a zero, which leaves it as it was
    // (light here is never -0).
    for (((r, g), b), (&w, &l)) in luxels.zip(weights.iter().zip(lit)) {
        let w = f64::from(w) * total;
        let w = if (l == State::Lit) & (w > 0.0) & (strongest * w >= GATE) {
            w
        } else {
            0.0
        };
        *r += (w * cr) as f32;
        *g += (w * cg) as f32;
        *b += (w * cb) as f32;
    }
}

/// Adds to `out` (per style and luxel of `r`, at `points`) the light of the emitters of
/// `rows`, at their weights, where nothing blocks it.
fn light_batch(
    scene: &TraceScene,
    r: &Receivers,
    points: &[DVec3],
    rows: &WeightRows,
    out: &mut StyleColumns,
    counts: &mut BounceCounts,
) {
    let n = points.len();
    let from: Vec<DVec3> = rows.emitters.iter().map(|w| w.emitter.point).collect();
    // A weak emitter's visibility is one segment's, to a luxel drawn by weight.
    let weak: Vec<Option<usize>> = rows
        .emitters
        .iter()
        .enumerate()
        .map(|(k, w)| {
            let e = w.emitter;
            // The points of one face share its shadows: their weakness adds up.
            (f64::from(w.largest) * e.max_intensity() < WEAK * e.share)
                .then(|| weighted_pick(rows.row(k), w.total, e.key(r.face)))
        })
        .collect();
    let lit = see(scene, r, &from, &weak, points, rows, counts);
    for (k, weighed) in rows.emitters.iter().enumerate() {
        let (e, lit) = (weighed.emitter, &lit[k * n..(k + 1) * n]);
        // A weak emitter's segment decided for every luxel.
        if weak[k].is_some_and(|best| lit[best] == State::Blocked) {
            continue;
        }
        for &(style, color, total) in &e.styles {
            add_lit(out.style(style, n), rows.row(k), lit, color, total);
        }
    }
}

/// Every point `field`'s faces with light and a reflectance send their light from.
fn point_emitters(field: &Field, emission: Emission) -> Vec<PointEmitter> {
    let mut out = Vec::new();
    for (f, light) in field.light.iter().enumerate() {
        let (Some(light), Some(Some(rho)), Some(face)) =
            (light, field.reflectance.get(f), field.faces.get(f))
        else {
            continue;
        };
        let area = polygon_area(&face.points);
        let corners = corners(&face.points);
        if area < MIN_AREA || corners.is_empty() {
            continue;
        }
        let at = match emission {
            Emission::Middle => vec![corners.center()],
            Emission::MiddleAndCorners => {
                let mut at = vec![corners.center()];
                at.extend_from_slice(&corners.points);
                at
            }
            Emission::Diced(size) => {
                // However small the pieces are asked to be, no face is cut into more than about
                // DICED_ACROSS² of them.
                let b = corners.bounds();
                let longest = (b.maxs - b.mins).max_element();
                let size = size.max(longest / DICED_ACROSS);
                let mut at = Vec::new();
                dice(corners.clone(), size, &mut |piece| at.push(piece.center()));
                at
            }
        };
        let share = 1.0 / at.len() as f64;
        let mut styles = Vec::new();
        for (style, luxels) in light {
            let n = luxels.len().max(1) as f64;
            let mut mean = [0.0f64; 3];
            for l in luxels {
                for k in 0..3 {
                    mean[k] += f64::from(l[k]) / n;
                }
            }
            let emit: [f64; 3] = std::array::from_fn(|k| mean[k] * f64::from(rho[k]));
            let strongest = emit[0].max(emit[1]).max(emit[2]);
            if strongest <= 0.0 {
                continue;
            }
            let color = if strongest > 1.0 {
                emit.map(|c| c / strongest)
            } else {
                emit
            };
            styles.push((*style, color.map(|c| c as f32), strongest * area * share));
        }
        if styles.is_empty() {
            continue;
        }
        let normal = face.plane.normal;
        let brightest = styles.iter().map(|s| s.2).fold(0.0, f64::max);
        out.extend(at.into_iter().map(|p| PointEmitter {
            face: f,
            point: p + normal,
            normal,
            styles: styles.clone(),
            share,
            brightest,
        }));
    }
    out
}

/// The points of `points` that are corners of the outline: those on a straight edge between
/// their neighbours left out.
fn corners(points: &[DVec3]) -> Winding {
    let n = points.len();
    let kept = (0..n)
        .filter(|&i| {
            let before = (points[i] - points[(i + n - 1) % n]).normalize_or_zero();
            let after = (points[(i + 1) % n] - points[i]).normalize_or_zero();
            before.dot(after) < STRAIGHT
        })
        .map(|i| points[i]);
    Winding::new(kept.collect())
}

/// Cuts `w` by planes across the axes at multiples of `size` until no piece spans one, and
/// hands each piece to `piece`. A piece reaching less than [`DICE_OVERLAP`] past such a plane is
/// not cut there, so pieces are never slivers along the grid.
fn dice(w: Winding, size: f64, piece: &mut impl FnMut(&Winding)) {
    if w.is_empty() {
        return;
    }
    let b = w.bounds();
    let (lo, hi) = (b.mins.to_array(), b.maxs.to_array());
    let cell = |c: f64| (c / size).floor();
    let Some(axis) = (0..3).find(|&a| cell(lo[a] + DICE_OVERLAP) < cell(hi[a] - DICE_OVERLAP))
    else {
        piece(&w);
        return;
    };
    let mut normal = DVec3::ZERO;
    normal[axis] = 1.0;
    let plane = Plane::new(normal, size * (1.0 + cell(lo[axis] + DICE_OVERLAP)));
    match w.into_split(&plane) {
        Split::Both { front, back } => {
            dice(front, size, piece);
            dice(back, size, piece);
        }
        Split::Front(w) | Split::Back(w) | Split::On { winding: w, .. } => piece(&w),
    }
}

/// Whether a luxel sees an emitter. The known answers are one bit each, so that the bits of
/// several luxels or-ed together tell whether those known agree ([`State::agreed`]).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(u8)]
enum State {
    Unknown = 0,
    Lit = 1,
    Blocked = 2,
}

impl State {
    /// The answer of those of `states` that are known, when there are some and they agree.
    fn agreed(states: [State; 4]) -> Option<State> {
        match states.iter().fold(0, |bits, &s| bits | s as u8) {
            1 => Some(State::Lit),
            2 => Some(State::Blocked),
            _ => None,
        }
    }
}

/// The coarsest grid's step, in luxels, at which [`see`] starts.
const FIRST_STEP: usize = 4;

/// For each of the points `from` (row-major by point) and each luxel of `r` with a weight
/// there: whether nothing blocks the segment between them ([`State::Lit`]). Coarse to fine:
/// segments to the luxels of a grid every [`FIRST_STEP`] luxels (and the last row and column)
/// first; then on each grid of half the step, segments only to luxels whose coarser cell's
/// corners disagree, the others taking the corners' answer. A shadow narrower than the coarse
/// grid that falls between its luxels is missed; bounced light from a point is rarely that
/// sharp. A point `weak` names (with the luxel drawn for it) is decided by that luxel's one
/// segment (see [`WEAK`]). Each step's segments, from every point, go 16 to a packet.
fn see(
    scene: &TraceScene,
    r: &Receivers,
    from: &[DVec3],
    weak: &[Option<usize>],
    points: &[DVec3],
    rows: &WeightRows,
    counts: &mut BounceCounts,
) -> Vec<State> {
    let (w, h) = (r.width, r.height);
    let n = w * h;
    let mut state = vec![State::Unknown; rows.emitters.len() * n];
    let mut packet = RayPacket16::new();
    // Segments to trace: (emitter, luxel).
    let mut rays: Vec<(usize, usize)> = Vec::new();
    let mut step = FIRST_STEP;
    while step >= 1 {
        // Per column and per row, the ends of the coarser grid's cell it lies in.
        let coarse = step * 2;
        let cells = |size: usize| -> Vec<(usize, usize)> {
            (0..size)
                .map(|x| {
                    let lo = x / coarse * coarse;
                    (lo, (lo + coarse).min(size - 1))
                })
                .collect()
        };
        let (cell_x, cell_y) = (cells(w), cells(h));
        let (xs, ys) = (crate::grid::grid(w, step), crate::grid::grid(h, step));
        rays.clear();
        for (k, weak) in weak.iter().enumerate() {
            let at = k * n;
            if let Some(best) = *weak {
                if step == FIRST_STEP {
                    rays.push((k, best));
                }
                continue;
            }
            let state_of = |state: &[State], x: usize, y: usize| state[at + y * w + x];
            let weights = rows.row(k);
            for &y in &ys {
                let (y0, y1) = cell_y[y];
                for &x in &xs {
                    let j = at + y * w + x;
                    if weights[y * w + x] == 0.0 || state[j] != State::Unknown {
                        continue;
                    }
                    if step == FIRST_STEP {
                        rays.push((k, y * w + x));
                        continue;
                    }
                    let (x0, x1) = cell_x[x];
                    let corners = [
                        state_of(&state, x0, y0),
                        state_of(&state, x1, y0),
                        state_of(&state, x0, y1),
                        state_of(&state, x1, y1),
                    ];
                    match State::agreed(corners) {
                        Some(a) => state[j] = a,
                        None => rays.push((k, y * w + x)),
                    }
                }
            }
        }
        for chunk in rays.chunks(16) {
            packet.clear();
            for (lane, &(k, i)) in chunk.iter().enumerate() {
                let origin = from[k];
                let to = points[i] - origin;
                let dist = to.length().max(f64::from(MIN_DISTANCE));
                packet.set(
                    lane,
                    origin.as_vec3().to_array(),
                    (to / dist).as_vec3().to_array(),
                    crate::trace::RAY_START,
                    // Stopping where a ray from the luxel would start.
                    (dist as f32 - crate::trace::RAY_START).max(0.0),
                );
            }
            let blocked = scene.occluded16_scattered(&mut packet, r.model);
            counts.rays += chunk.len() as u64;
            for (lane, &(k, i)) in chunk.iter().enumerate() {
                state[k * n + i] = if blocked & (1 << lane) != 0 {
                    State::Blocked
                } else {
                    State::Lit
                };
            }
        }
        if step == FIRST_STEP {
            for (k, best) in weak.iter().enumerate() {
                if let Some(best) = best {
                    let answer = state[k * n + best];
                    state[k * n..(k + 1) * n].fill(answer);
                }
            }
        }
        step /= 2;
    }
    state
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lights::BounceSettings;
    use quake_formats::geom::Plane;

    /// An upward 20 × 10 face at height 0 whose outline also passes through (10, 0, 0), a
    /// T-junction point on its long edge.
    fn floor() -> FaceGeom {
        let points = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 10.0, 0.0),
            DVec3::new(20.0, 10.0, 0.0),
            DVec3::new(20.0, 0.0, 0.0),
            DVec3::new(10.0, 0.0, 0.0),
        ];
        FaceGeom::for_test(0, 0, points, Plane::new(DVec3::Z, 0.0))
    }

    proptest::proptest! {
        /// The blockwise maximum is the plain one, on rows of any length.
        #[test]
        fn largest_weight_is_the_maximum(
            weights in proptest::collection::vec(0.0f32..1e3, 0..40),
        ) {
            let plain = weights.iter().fold(0.0f32, |m, &w| if w > m { w } else { m });
            let (largest, total) = largest_and_total(&weights);
            proptest::prop_assert_eq!(largest.to_bits(), plain.to_bits());
            let sum: f32 = weights.iter().sum();
            proptest::prop_assert!((total - sum).abs() <= 1e-3 * sum.max(1.0));
        }

        /// A weak emitter's segment goes to a luxel with weight, whatever the draw.
        #[test]
        fn the_picked_luxel_has_weight(
            weights in proptest::collection::vec(
                proptest::prop_oneof![proptest::strategy::Just(0.0f32), 0.0f32..1e3], 1..60),
            key in proptest::num::u64::ANY,
        ) {
            let (_, total) = largest_and_total(&weights);
            let i = weighted_pick(&weights, total, key);
            proptest::prop_assert!(i < weights.len());
            if total > 0.0 {
                proptest::prop_assert!(weights[i] > 0.0, "{i} {weights:?}");
            }
        }

        /// Where [`under_gate`] says a flat face's luxels take nothing from an emitter, the
        /// weighing gives every one of them zero: culling by the bound changes no luxel.
        #[test]
        fn under_gate_culls_only_what_weighing_zeroes(
            at in proptest::collection::vec((-200.0f32..200.0, -200.0f32..200.0), 1..30),
            offset in (-3000.0f32..3000.0, -3000.0f32..3000.0, -3000.0f32..3000.0),
            tilt in (-1.0f64..1.0, -1.0f64..1.0, 0.05f64..1.0),
            emitter in (-400.0f64..400.0, -400.0f64..400.0, -2.0f64..40.0),
            intensity in 0.01f64..1e6,
        ) {
            let n_r = DVec3::new(tilt.0, tilt.1, tilt.2).normalize();
            let (u, v) = (n_r.any_orthonormal_pair().0, n_r.any_orthonormal_pair().1);
            let base = Vec3::new(offset.0, offset.1, offset.2).as_dvec3();
            let points: Vec<[f32; 3]> = at
                .iter()
                .map(|&(x, y)| (base + u * f64::from(x) + v * f64::from(y) + n_r).as_vec3().to_array())
                .collect();
            let normals = vec![n_r.as_vec3().to_array(); points.len()];
            let mut e = emitters_of([100.0, 50.0, 0.0], Emission::Middle).remove(0);
            e.point = base + u * emitter.0 + v * emitter.1 + n_r * emitter.2;
            e.normal = (u * 0.3 + n_r * 0.7).normalize();
            e.styles[0].2 = intensity;
            e.brightest = intensity;
            let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
            for &p in &points {
                let p = Vec3::from(p).as_dvec3();
                lo = lo.min(p);
                hi = hi.max(p);
            }
            let kernel = 0.5;
            let n_r32 = Vec3::from(normals[0]).as_dvec3();
            if under_gate(&e, n_r32, (lo, hi), kernel * intensity / GATE) {
                let luxels = Luxels::new(&points, &normals, points.len());
                let mut weights = vec![1.0f32; points.len()];
                weigh(&e, &luxels, kernel as f32, (GATE / intensity) as f32, false, &mut weights);
                proptest::prop_assert!(weights.iter().all(|&w| w == 0.0), "{:?}", weights);
            }
        }

        /// A face's row of weights, weighed in whole vectors over luxels padded to a multiple of
        /// eight, holds for each luxel the weight weighing it alone gives, bit for bit, then
        /// zeros; with the largest and the sum of those weights. A row of zeros is not kept.
        #[test]
        fn padded_rows_weigh_each_luxel_as_weighing_it_alone_does(
            luxels in proptest::collection::vec(
                ((-300.0f32..300.0, -300.0f32..300.0, -300.0f32..300.0), (-1.0f32..1.0, -1.0f32..1.0)),
                1..40,
            ),
            emitter in (-300.0f64..300.0, -300.0f64..300.0, 0.0f64..300.0),
            two_sided in proptest::bool::ANY,
        ) {
            let points: Vec<[f32; 3]> = luxels.iter().map(|&((x, y, z), _)| [x, y, z]).collect();
            let normals: Vec<[f32; 3]> = luxels
                .iter()
                .map(|&(_, (a, b))| Vec3::new(a, b, 1.0).normalize().to_array())
                .collect();
            let mut e = emitters_of([100.0, 50.0, 0.0], Emission::Middle).remove(0);
            e.point = DVec3::new(emitter.0, emitter.1, emitter.2);
            let (kernel, gate) = (0.5f32, 1e-6f32);
            let mut rows = WeightRows::new(points.len());
            let at = Luxels::new(&points, &normals, rows.stride);
            rows.push(&e, &at, kernel, gate, two_sided);
            let alone: Vec<f32> = (0..points.len())
                .map(|i| {
                    let one = Luxels::new(&points[i..=i], &normals[i..=i], 1);
                    let mut w = [f32::NAN];
                    weigh(&e, &one, kernel, gate, two_sided, &mut w);
                    w[0]
                })
                .collect();
            if alone.iter().all(|&w| w == 0.0) {
                proptest::prop_assert!(rows.emitters.is_empty() && rows.weights.is_empty());
            } else {
                proptest::prop_assert_eq!(rows.stride % ROW_LANES, 0);
                proptest::prop_assert_eq!(rows.weights.len(), rows.stride);
                let bits = |w: &[f32]| w.iter().map(|w| w.to_bits()).collect::<Vec<_>>();
                proptest::prop_assert_eq!(bits(rows.row(0)), bits(&alone));
                proptest::prop_assert!(rows.weights[points.len()..].iter().all(|&w| w == 0.0));
                let (largest, total) = largest_and_total(&alone);
                proptest::prop_assert_eq!(rows.emitters[0].largest, largest);
                proptest::prop_assert_eq!(rows.emitters[0].total, total);
            }
        }

        /// Adding a row's light without branches changes, bit for bit, what adding it to the lit
        /// luxels it brings at least the gate changes, and nothing else.
        #[test]
        fn adding_lit_light_in_columns_adds_only_to_lit_luxels_over_the_gate(
            luxels in proptest::collection::vec(
                (
                    proptest::prop_oneof![proptest::strategy::Just(0.0f32), 0.0f32..1e-3, 0.0f32..10.0],
                    0u8..3,
                    (0.0f32..100.0, 0.0f32..100.0, 0.0f32..100.0),
                ),
                0..40,
            ),
            color in (0.0f32..1.0, 0.0f32..1.0, 0.0f32..1.0),
            total in 0.0f64..1e4,
        ) {
            let state = |s: u8| [State::Unknown, State::Lit, State::Blocked][usize::from(s)];
            let weights: Vec<f32> = luxels.iter().map(|l| l.0).collect();
            let lit: Vec<State> = luxels.iter().map(|l| state(l.1)).collect();
            let color = [color.0, color.1, color.2];
            let mut plain: Vec<[f32; 3]> = luxels.iter().map(|l| [l.2.0, l.2.1, l.2.2]).collect();
            let strongest = f64::from(color[0].max(color[1]).max(color[2]));
            for ((v, &w), &l) in plain.iter_mut().zip(&weights).zip(&lit) {
                let w = f64::from(w) * total;
                if l == State::Lit && w > 0.0 && strongest * w >= GATE {
                    for (v, c) in v.iter_mut().zip(color) {
                        *v += (w * f64::from(c)) as f32;
                    }
                }
            }
            // As each vector build this CPU runs compiles it.
            let each = crate::simd::builds_here(
                #[inline(always)]
                || {
                    let mut columns: [Vec<f32>; 3] = std::array::from_fn(|c| {
                        luxels.iter().map(|l| [l.2.0, l.2.1, l.2.2][c]).collect()
                    });
                    add_lit_any(&mut columns, &weights, &lit, color, total);
                    columns
                },
            );
            for (build, columns) in each {
                for (i, v) in plain.iter().enumerate() {
                    for c in 0..3 {
                        proptest::prop_assert_eq!(
                            columns[c][i].to_bits(), v[c].to_bits(), "{:?}", build
                        );
                    }
                }
            }
        }

        /// The column-wise cull keeps exactly the emitters the plain tests keep (in front of a
        /// one-sided face, facing its box, bright enough at its distance), and a group is
        /// ruled out whole only when none of them is kept.
        #[test]
        fn may_light_keeps_what_the_plain_tests_keep(
            emitters in proptest::collection::vec(
                (
                    (-600.0f64..600.0, -600.0f64..600.0, -600.0f64..600.0),
                    (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
                    0.0f64..3e3,
                ),
                1..150,
            ),
            tilt in (-1.0f64..1.0, -1.0f64..1.0, -1.0f64..1.0),
            dist in -300.0f64..300.0,
            corner in (-400.0f64..400.0, -400.0f64..400.0, -400.0f64..400.0),
            size in (0.0f64..200.0, 0.0f64..200.0, 0.0f64..200.0),
            two_sided in proptest::bool::ANY,
        ) {
            let unit = |(x, y, z): (f64, f64, f64)| DVec3::new(x, y, z).try_normalize();
            let emitters: Vec<PointEmitter> = emitters
                .iter()
                .map(|&((x, y, z), n, brightest)| PointEmitter {
                    face: 0,
                    point: DVec3::new(x, y, z),
                    normal: unit(n).unwrap_or(DVec3::Z),
                    styles: Vec::new(),
                    share: 1.0,
                    brightest,
                })
                .collect();
            let lo = DVec3::new(corner.0, corner.1, corner.2);
            let cull = Cull {
                plane: Plane::new(unit(tilt).unwrap_or(DVec3::X), dist),
                two_sided,
                lo,
                hi: lo + DVec3::new(size.0, size.1, size.2),
                kernel: 0.5,
            };
            let plain = |e: &PointEmitter| {
                let far = DVec3::select(e.normal.cmpgt(DVec3::ZERO), cull.hi, cull.lo);
                let nearest = e.point.clamp(cull.lo, cull.hi).distance_squared(e.point);
                (cull.two_sided || cull.plane.distance(e.point) > 0.0)
                    && e.normal.dot(far - e.point) >= 0.0
                    && cull.kernel * e.brightest / nearest.max(HOTSPOT_CLAMP * HOTSPOT_CLAMP)
                        >= GATE
            };
            let columns = EmitterColumns::new(&emitters);
            for (g, group) in emitters.chunks(GROUP).enumerate() {
                let first = g * GROUP;
                let expected = group
                    .iter()
                    .enumerate()
                    .fold(0u64, |bits, (i, e)| bits | u64::from(plain(e)) << i);
                let each = crate::simd::builds_here(
                    #[inline(always)]
                    || may_light_any(&columns, first, &cull),
                );
                for (build, kept) in each {
                    proptest::prop_assert_eq!(kept, expected, "{:?}", build);
                }
                if !EmitterGroup::new(group, |_| &[]).may_light(&cull) {
                    proptest::prop_assert_eq!(expected, 0);
                }
            }
        }

        /// Every vector build of the weighing this CPU runs gives the baseline's bits, one- and
        /// two-sided.
        #[test]
        fn weigh_copies_agree(
            at in proptest::collection::vec(
                (-300.0f32..300.0, -300.0f32..300.0, -50.0f32..50.0),
                1..40,
            ),
            two_sided in proptest::bool::ANY,
        ) {
            let e = &emitters_of([100.0, 50.0, 0.0], Emission::Middle)[0];
            let points: Vec<[f32; 3]> = at.iter().map(|&(x, y, z)| [x, y, z]).collect();
            let normals = vec![[0.0, 0.6, -0.8]; points.len()];
            let luxels = Luxels::new(&points, &normals, points.len());
            let mut any = vec![0.0f32; points.len()];
            weigh_any(e, &luxels, 0.5, 1e-4, two_sided, &mut any);
            let each = crate::simd::builds_here(
                #[inline(always)]
                || {
                    let mut weights = vec![0.0f32; points.len()];
                    weigh_any(e, &luxels, 0.5, 1e-4, two_sided, &mut weights);
                    weights
                },
            );
            let bits = |v: &[f32]| v.iter().map(|w| w.to_bits()).collect::<Vec<_>>();
            for (build, weights) in each {
                proptest::prop_assert_eq!(bits(&weights), bits(&any), "{:?}", build);
            }
        }
    }

    fn emitters_of(light: [f32; 3], emission: Emission) -> Vec<PointEmitter> {
        emitters_of_face(floor(), light, emission)
    }

    fn emitters_of_face(face: FaceGeom, light: [f32; 3], emission: Emission) -> Vec<PointEmitter> {
        let faces = [face];
        let reflectance = [Some([0.5; 3])];
        // Two luxels: the mean is `light`.
        let lit = [Some(vec![(0u8, vec![[0.0; 3], light.map(|c| 2.0 * c)])])];
        let settings = BounceSettings {
            passes: 1,
            scale: 1.0,
            color_scale: 0.0,
            styled: false,
            dirt: None,
            emission: crate::bounce::EmissiveQuality::Low,
            subdivision: 64.0,
        };
        point_emitters(&Field::new(&faces, &reflectance, &lit, &settings), emission)
    }

    /// Four luxels' answers agree when those known are all the same: as many as are known.
    #[test]
    fn corners_agree_when_every_known_one_says_the_same() {
        let all = [State::Unknown, State::Lit, State::Blocked];
        for a in all {
            for b in all {
                for c in all {
                    for d in all {
                        let mut known = [a, b, c, d].into_iter().filter(|&s| s != State::Unknown);
                        let plain = match known.next() {
                            Some(first) if known.all(|s| s == first) => Some(first),
                            _ => None,
                        };
                        assert_eq!(
                            State::agreed([a, b, c, d]),
                            plain,
                            "{a:?} {b:?} {c:?} {d:?}"
                        );
                    }
                }
            }
        }
    }

    /// A weak emitter is seen or not by the face as the segment to one luxel drawn in
    /// proportion to the weights says: over many emitters, each luxel decides its share, not
    /// only the one lit most (which, against the emitter's own face, is blocked more often).
    #[test]
    fn weak_segments_go_to_luxels_in_proportion_to_their_weight() {
        let weights = [1.0, 0.0, 3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 4.0];
        let (largest, total) = largest_and_total(&weights);
        assert_eq!((largest, total), (4.0, 8.0));
        let mut picks = [0usize; 10];
        for key in 0..8000 {
            picks[weighted_pick(&weights, total, crate::bounce::point_key(7, key, 1))] += 1;
        }
        for (i, &w) in weights.iter().enumerate() {
            let expected = 1000.0 * f64::from(w);
            assert!((picks[i] as f64 - expected).abs() <= 120.0, "{picks:?}");
        }
        assert_eq!(weighted_pick(&[0.0; 3], 0.0, 5), 0);
    }

    #[test]
    fn a_face_sends_its_mean_reflected_light_from_a_unit_in_front_of_its_middle() {
        let e = emitters_of([100.0, 50.0, 0.0], Emission::Middle);
        assert_eq!(e.len(), 1);
        // The T-junction point does not pull the middle towards it.
        assert!(
            e[0].point.distance(DVec3::new(10.0, 5.0, 1.0)) < 1e-9,
            "{:?}",
            e[0].point
        );
        // Reflected 50 25 0: colour over its strongest channel, intensity 50 × 200 units².
        let (style, color, intensity) = e[0].styles[0];
        assert_eq!((style, color), (0, [1.0, 0.5, 0.0]));
        assert!((intensity - 50.0 * 200.0).abs() < 1e-6, "{intensity}");
    }

    #[test]
    fn light_under_one_unit_keeps_its_colour_unscaled() {
        // ericw-tools' rule: only a strongest channel above 1 is divided out.
        let e = emitters_of([1.0, 0.5, 0.0], Emission::Middle);
        let (_, color, intensity) = e[0].styles[0];
        assert_eq!(color, [0.5, 0.25, 0.0]);
        assert!((intensity - 0.5 * 200.0).abs() < 1e-6, "{intensity}");
    }

    #[test]
    fn medium_adds_the_corners_and_shares_the_light_among_the_points() {
        let e = emitters_of([100.0; 3], Emission::MiddleAndCorners);
        assert_eq!(e.len(), 5, "the middle and four corners");
        assert!(e.iter().all(|p| p.point.z == 1.0));
        let total: f64 = e.iter().map(|p| p.styles[0].2).sum();
        assert!((total - 50.0 * 200.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn high_dices_the_face_and_sends_from_each_piece_middle() {
        // The 20 × 10 floor diced every 8 units: cuts at x 8 and 16 and y 8 (a piece reaching
        // less than a unit past a cut, none here, would not be cut).
        let e = emitters_of([100.0; 3], Emission::Diced(8.0));
        let mut middles: Vec<(f64, f64)> = e.iter().map(|p| (p.point.x, p.point.y)).collect();
        middles.sort_by(|a, b| a.partial_cmp(b).unwrap());
        let expected = [
            (4.0, 4.0),
            (4.0, 9.0),
            (12.0, 4.0),
            (12.0, 9.0),
            (18.0, 4.0),
            (18.0, 9.0),
        ];
        assert_eq!(middles.len(), expected.len(), "{middles:?}");
        for (got, want) in middles.iter().zip(expected) {
            assert!(
                (got.0 - want.0).abs() < 1e-9 && (got.1 - want.1).abs() < 1e-9,
                "{middles:?}"
            );
        }
        assert!(e.iter().all(|p| p.point.z == 1.0));
        let total: f64 = e.iter().map(|p| p.styles[0].2).sum();
        assert!((total - 50.0 * 200.0).abs() < 1e-6, "{total}");
        // Pieces no wider than the face: one point, the middle.
        assert_eq!(emitters_of([100.0; 3], Emission::Diced(64.0)).len(), 1);
        // Pieces asked a unit wide: a piece reaching less than a unit past a cut is not cut
        // there, so they come two units wide, 10 by 5.
        assert_eq!(emitters_of([100.0; 3], Emission::Diced(1.0)).len(), 50);
    }

    #[test]
    fn a_large_face_diced_finely_keeps_a_bounded_number_of_points() {
        let points = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(0.0, 4096.0, 0.0),
            DVec3::new(4096.0, 4096.0, 0.0),
            DVec3::new(4096.0, 0.0, 0.0),
        ];
        let square = FaceGeom::for_test(0, 0, points, Plane::new(DVec3::Z, 0.0));
        let e = emitters_of_face(square, [100.0; 3], Emission::Diced(1.0));
        // 64 pieces along each side, not two million.
        assert_eq!(e.len(), 64 * 64);
    }

    #[test]
    fn dicing_leaves_no_piece_across_a_cut() {
        let square = Winding::new(vec![
            DVec3::new(-100.0, -60.0, 5.0),
            DVec3::new(-100.0, 70.0, 5.0),
            DVec3::new(90.0, 70.0, 5.0),
            DVec3::new(90.0, -60.0, 5.0),
        ]);
        let mut area = 0.0;
        let mut pieces = 0;
        dice(square.clone(), 32.0, &mut |w| {
            pieces += 1;
            area += w.area();
            let b = w.bounds();
            for axis in 0..2 {
                let (lo, hi) = (b.mins[axis], b.maxs[axis]);
                assert!(
                    ((lo + 1.0) / 32.0).floor() >= ((hi - 1.0) / 32.0).floor(),
                    "{b:?}"
                );
            }
        });
        // x: -100..-96, 32 wide up to 64, then 64..90 (7); y: -60..-32, 32 wide up to 64,
        // then 64..70 (5).
        assert_eq!(pieces, 7 * 5);
        assert!((area - square.area()).abs() < 1e-6, "{area}");
    }

    proptest::proptest! {
        /// T-junction points on a rectangle's edges change neither its area nor its corners.
        #[test]
        fn straight_edge_points_are_not_corners(
            x in -4096.0f64..4096.0, y in -4096.0f64..4096.0,
            w in 1.0f64..512.0, h in 1.0f64..512.0,
            cuts in proptest::collection::vec((0usize..4, 0.05f64..0.95), 0..6),
        ) {
            let rect = [
                DVec3::new(x, y, 0.0),
                DVec3::new(x, y + h, 0.0),
                DVec3::new(x + w, y + h, 0.0),
                DVec3::new(x + w, y, 0.0),
            ];
            let mut points = Vec::new();
            for (k, &corner) in rect.iter().enumerate() {
                points.push(corner);
                let next = rect[(k + 1) % 4];
                let mut along: Vec<f64> =
                    cuts.iter().filter(|c| c.0 == k).map(|c| c.1).collect();
                along.sort_by(f64::total_cmp);
                points.extend(along.iter().map(|&t| corner.lerp(next, t)));
            }
            let area = polygon_area(&points);
            proptest::prop_assert!((area - w * h).abs() < 1e-6 * w * h);
            let found = corners(&points);
            proptest::prop_assert_eq!(found.len(), 4, "{:?}", found);
            let middle = found.center();
            proptest::prop_assert!(middle.distance(DVec3::new(x + w / 2.0, y + h / 2.0, 0.0)) < 1e-6);
        }
    }

    #[test]
    fn a_dark_or_tiny_face_sends_nothing() {
        assert!(emitters_of([0.0; 3], Emission::Middle).is_empty());
        let sliver = [
            DVec3::ZERO,
            DVec3::new(0.0, 0.5, 0.0),
            DVec3::new(1.0, 0.5, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
        ];
        let area = Winding::new(sliver.to_vec()).area();
        assert!((area - 0.5).abs() < 1e-12 && area < MIN_AREA);
    }
}
