//! Which samples a light reaches: shadow rays 16 to a packet, samples at one point sharing
//! a ray, and on supersampled faces (or for the many directions of a soft sun) probes first,
//! with the rays between them traced only where the probes disagree (on a luxel the probes do
//! not settle, its hull's corners first: [`super::hulls`]). A light too faint on the
//! face to matter gets a handful of probes for the whole face, and samples whose light is not
//! used (in solid, with open samples beside them) cast no ray.

use crate::bits::ones;
use crate::embree::RayPacket16;
use crate::grid::SampleGrid;
use crate::samples::FaceSamples;

use super::hulls::{LuxelHulls, every_sample};

/// What a luxel's probe ray (one sub-sample per luxel) found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Probe {
    /// The probe sample takes nothing from this light (gated, close, off the cone).
    Missing,
    Reaches,
    Blocked,
}

/// Buffers for [`VisibilityScratch::trace`], reused across a face's lights.
#[derive(Debug, Default)]
pub struct VisibilityScratch {
    /// Per sample: its ray reaches the light (meaningful where `value != 0`).
    pub lit: Vec<bool>,
    /// Per sample: the first sample at the same point, whose ray stands for both.
    pub first_at: Vec<usize>,
    /// Per sample: its ray was traced for the current light.
    traced: Vec<bool>,
    todo: Vec<usize>,
    unique: Vec<usize>,
    probes: Vec<Probe>,
    /// Per sample: its light is not used, so it casts no ray (empty: every sample's is).
    unused: Vec<bool>,
    /// Per luxel of a supersampled face, which of its samples are moved, occluded, unused.
    luxel_bits: Vec<LuxelBits>,
    /// The corners of luxels' samples, for the luxels that trace their sub-samples.
    hulls: LuxelHulls,
    /// Luxels with samples inside their hull, waiting for its corners' answers.
    deferred: Vec<usize>,
}

/// A supersampled face's luxels have at most this many samples when they are traced
/// adaptively, one bit each in [`LuxelBits`] (`--extra4` has 16; the reference, which has
/// more, traces every sample).
const MAX_ADAPTIVE_SAMPLES: usize = 64;

/// One luxel's samples, a bit each (sample `k` of the luxel is bit `k`).
#[derive(Debug, Default, Clone, Copy)]
struct LuxelBits {
    /// Moved onto the face or out of solid ([`FaceSamples::moved`]).
    moved: u64,
    occluded: u64,
    /// Casting no ray (see [`VisibilityScratch::unused`]).
    unused: u64,
}

impl LuxelBits {
    /// Every sample lies on the grid, in the open.
    fn on_grid(self) -> bool {
        self.moved | self.occluded == 0
    }
}

/// A bit for each of `items` (at most 64) that `set` holds of (item `k` is bit `k`). Whole
/// eights of items are answered as the bytes of one word, which the compiler compares
/// together; a loop shifting each answer into place on its own keeps it from doing so.
fn bits_where<T: Copy>(items: &[T], set: impl Fn(T) -> bool) -> u64 {
    debug_assert!(items.len() <= 64, "{} items", items.len());
    let mut bits = 0;
    let mut eights = items.chunks_exact(8);
    let mut at = 0;
    for eight in eights.by_ref().take(8) {
        let word = u64::from_le_bytes(std::array::from_fn(|k| u8::from(set(eight[k]))));
        bits |= byte_bits(word) << at;
        at += 8;
    }
    for (k, &item) in eights.remainder().iter().enumerate() {
        bits |= u64::from(set(item)) << (at + k);
    }
    bits
}

/// The eight bytes of `word`, each 0 or 1, as eight bits (byte `k` is bit `k`).
fn byte_bits(word: u64) -> u64 {
    // Each byte's bit is carried to the top byte by the multiplication, at its own place.
    word.wrapping_mul(0x0102_0408_1020_4080) >> 56
}

/// The bits of `values` that are not zero.
fn valued(values: &[f64]) -> u64 {
    bits_where(values, |v| v != 0.0)
}

/// Supersampled faces at least this many samples a luxel across trace the corners of a
/// luxel's samples before the rest ([`LuxelHulls`]); fewer leave nothing inside them.
const MIN_HULL_AXIS: usize = 4;

impl VisibilityScratch {
    /// Ready for `samples`' face; `raw_light_read` as [`super::TraceSetup`] says.
    pub fn start_face(&mut self, samples: &FaceSamples, raw_light_read: bool) {
        self.first_at = samples.first_at_same_point();
        let per = samples.per_luxel();
        if samples.per_axis >= MIN_HULL_AXIS && per <= MAX_ADAPTIVE_SAMPLES {
            self.hulls.start_face(samples);
        }
        // The light of an occluded sample is replaced by its open neighbours' when the face
        // has open samples ([`crate::luxels`]): only a face without any needs their rays.
        self.unused.clear();
        if !raw_light_read && samples.occluded.contains(&false) {
            let (occluded, first_at) = (&samples.occluded, &self.first_at);
            // A sample sharing the ray of an open one at its point still casts that ray
            // when asked (see `cast`): dropping it would leave the open one to its probe.
            self.unused
                .extend((0..occluded.len()).map(|i| occluded[i] && occluded[first_at[i]]));
        }
        self.luxel_bits.clear();
        if per > 1 && per <= MAX_ADAPTIVE_SAMPLES {
            // Flags kept empty when none is set (occluded, unused) give no bits.
            let bits = |flags: &[bool], l: usize| {
                flags
                    .get(l * per..(l + 1) * per)
                    .map_or(0, |f| bits_where(f, |set| set))
            };
            self.luxel_bits
                .extend((0..samples.luxels()).map(|l| LuxelBits {
                    moved: bits(&samples.moved, l),
                    occluded: bits(&samples.occluded, l),
                    unused: bits(&self.unused, l),
                }));
        }
    }

    /// Clears what the last light left for a face of `n` samples.
    fn start_light(&mut self, n: usize) {
        self.lit.clear();
        self.lit.resize(n, false);
        self.traced.clear();
        self.traced.resize(n, false);
        self.todo.clear();
    }

    /// Fills `lit` for every sample with a non-zero `value`; returns the
    /// rays cast. `ray(i)` is sample `i`'s (origin, direction, length) and
    /// `reaches` the lanes of a packet whose rays get through.
    ///
    /// `adaptive` (supersampled faces only): first one probe ray per luxel;
    /// a luxel whose probe agrees with the probes of all 8 neighbours takes
    /// that answer for all its sub-samples, the others (penumbrae, shadow
    /// edges, spots where a probe had no ray) trace every sub-sample, or, at
    /// [`MIN_HULL_AXIS`] and above, the corners of their hull first and the
    /// rest only where the corners disagree ([`LuxelHulls`]). A straight shadow
    /// edge through a luxel always separates its probe from a neighbour's, and
    /// two corners of its hull; only shadows thinner than a luxel can slip
    /// between. Moved samples (see [`FaceSamples::moved`]) are never answered by
    /// the neighbours' probes.
    pub fn trace(
        &mut self,
        samples: &FaceSamples,
        adaptive: bool,
        value: &[f64],
        ray: impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        mut reaches: impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        let n = value.len();
        self.start_light(n);
        let per = samples.per_luxel();
        if !adaptive || per == 1 || per > MAX_ADAPTIVE_SAMPLES {
            let unused = &self.unused;
            self.todo
                .extend((0..n).filter(|&i| value[i] != 0.0 && !is_unused(unused, i)));
            return self.cast(&ray, packet, &mut reaches);
        }
        let probe_sub = samples.middle_of(0);
        let luxels = samples.luxels();
        self.todo.extend(
            (0..luxels)
                .map(|l| samples.middle_of(l))
                .filter(|&i| value[i] != 0.0),
        );
        let mut rays = self.cast(&ray, packet, &mut reaches);
        self.probes.clear();
        self.probes.extend((0..luxels).map(|l| {
            let i = samples.middle_of(l);
            match (value[i] != 0.0, self.lit[i]) {
                (false, _) => Probe::Missing,
                (true, true) => Probe::Reaches,
                (true, false) => Probe::Blocked,
            }
        }));
        self.todo.clear();
        self.deferred.clear();
        let (w, h) = (samples.width, samples.height);
        let hulls_apply = samples.per_axis >= MIN_HULL_AXIS;
        let all = every_sample(per);
        let probe_bit = 1u64 << probe_sub;
        for l in 0..luxels {
            let (x, y) = (l % w, l / w);
            let probe = self.probes[l];
            let bits = self.luxel_bits[l];
            let uniform = bits.moved & probe_bit == 0
                && probe != Probe::Missing
                && (y.saturating_sub(1)..(y + 2).min(h)).all(|ny| {
                    (x.saturating_sub(1)..(x + 2).min(w))
                        .all(|nx| self.probes[ny * w + nx] == probe)
                });
            let first = l * per;
            let values = &value[first..first + per];
            let lit = &mut self.lit[first..first + per];
            let reaches = probe == Probe::Reaches;
            if uniform && bits.on_grid() {
                // The probe's own answer included (it is one of them).
                for (lit, &v) in lit.iter_mut().zip(values) {
                    *lit = reaches & (v != 0.0);
                }
                continue;
            }
            let valued = valued(values);
            // Moved points (the luxel overhangs the face, or something rests on it) are off
            // the grid the neighbour test assumes.
            let answered = if uniform { all & !bits.moved } else { 0 };
            for k in ones(answered) {
                lit[k] = reaches & (valued >> k & 1 != 0);
            }
            let wanted = valued & !answered & !probe_bit & !bits.unused;
            // Samples inside the hull of a luxel the neighbours do not answer for wait for the
            // hull's corners.
            let inside = if hulls_apply && !uniform {
                self.hulls.ask(samples, l, bits.on_grid());
                self.hulls.inside(l)
            } else {
                0
            };
            self.todo.extend(ones(wanted & !inside).map(|k| first + k));
            if wanted & inside != 0 {
                self.deferred.push(l);
            }
        }
        rays += self.cast(&ray, packet, &mut reaches);
        if !self.deferred.is_empty() {
            self.todo.clear();
            for &l in &self.deferred {
                let first = l * per;
                let inside = self.hulls.inside(l);
                // The probe (traced first) counts too when it lies inside.
                let asked = self.hulls.corners(l).iter().map(|&k| usize::from(k));
                let asked = asked.chain((inside & probe_bit != 0).then_some(probe_sub));
                let mut answer = None;
                let agreed = asked.into_iter().all(|k| {
                    let i = first + k;
                    value[i] != 0.0 && *answer.get_or_insert(self.lit[i]) == self.lit[i]
                });
                let waiting = valued(&value[first..first + per]) & inside & !probe_bit;
                match answer.filter(|_| agreed) {
                    Some(lit) => ones(waiting).for_each(|k| self.lit[first + k] = lit),
                    None => self.todo.extend(ones(waiting).map(|k| first + k)),
                }
            }
            rays += self.cast(&ray, packet, &mut reaches);
        }
        rays
    }

    /// For a light too faint on this face to be worth a ray per sample (see
    /// `FaceTrace::mark_faint`): a handful of probes (the brightest sample, and the middles of
    /// the corner and middle luxels) decide every sample into `lit` when they agree. Returns
    /// whether they did, and the rays cast; when they did not, the caller traces the light as
    /// usual ([`VisibilityScratch::trace`]). A shadow that falls between the probes is missed,
    /// but the lights this is used for are, together, too faint on the face for that to
    /// matter.
    pub fn probe_faint(
        &mut self,
        samples: &FaceSamples,
        value: &[f64],
        ray: &impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        reaches: &mut impl FnMut(&mut RayPacket16) -> u16,
    ) -> (bool, u64) {
        let n = value.len();
        self.start_light(n);
        let brightest = (0..n)
            .filter(|&i| value[i] != 0.0)
            .max_by(|&a, &b| value[a].abs().total_cmp(&value[b].abs()));
        let Some(brightest) = brightest else {
            return (true, 0);
        };
        let (w, h) = (samples.width, samples.height);
        let corners = [
            (0, 0),
            (w - 1, 0),
            (0, h - 1),
            (w - 1, h - 1),
            (w / 2, h / 2),
        ];
        self.todo.push(brightest);
        self.todo.extend(
            corners
                .map(|(x, y)| samples.middle_of(y * w + x))
                .into_iter()
                .filter(|&i| value[i] != 0.0),
        );
        let rays = self.cast(ray, packet, reaches);
        let answer = self.lit[brightest];
        let agreed = self.todo.iter().all(|&i| self.lit[i] == answer);
        if agreed {
            for (lit, &v) in self.lit.iter_mut().zip(value) {
                *lit = v != 0.0 && answer;
            }
        }
        (agreed, rays)
    }

    /// [`VisibilityScratch::trace`] for one of many directions of a sun or
    /// dome, one sample per luxel (the default mode): probes first, at the
    /// positions of `grid` (every [`super::suns`]'s stride-th luxel along each axis
    /// and the last row and column); a luxel between them that does not stand apart
    /// ([`FaceSamples::apart`]) takes the answer of its cell's probes
    /// when all of them got through or all were blocked; the others are
    /// traced. A shadow narrower than the cell can slip between the probes,
    /// but each direction carries at most a small part of its
    /// source's light.
    // Inlined into the sun loop, so its per-sample grid lookups are folded in, not called.
    #[inline]
    pub fn trace_probed(
        &mut self,
        samples: &FaceSamples,
        grid: &SampleGrid,
        value: &[f64],
        ray: impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        mut reaches: impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        debug_assert_eq!(samples.per_axis, 1);
        let n = value.len();
        self.start_light(n);
        let w = samples.width;
        let probe = |i: usize| value[i] != 0.0 && !samples.apart[i];
        for &y in &grid.ys {
            self.todo.extend(
                grid.xs
                    .iter()
                    .map(|&x| y * w + x)
                    .filter(|&i| value[i] != 0.0),
            );
        }
        let mut rays = self.cast(&ray, packet, &mut reaches);
        self.todo.clear();
        for y in 0..samples.height {
            for x in 0..w {
                let i = y * w + x;
                if value[i] == 0.0 {
                    continue;
                }
                let (corners, _, _) = grid.cell(x, y);
                if corners[0] == (x, y) {
                    continue; // a probe
                }
                let corners = corners.map(|(x, y)| y * w + x);
                let agreed = !samples.apart[i]
                    && corners.iter().all(|&c| probe(c))
                    && corners.iter().all(|&c| self.lit[c] == self.lit[corners[0]]);
                if agreed {
                    self.lit[i] = self.lit[corners[0]];
                } else {
                    self.todo.push(i);
                }
            }
        }
        rays += self.cast(&ray, packet, &mut reaches);
        rays
    }

    /// Traces the samples in `todo`, 16 to a packet, into `lit`; a sample
    /// at the same point as one already traced takes its answer.
    fn cast(
        &mut self,
        ray: &impl Fn(usize) -> ([f32; 3], [f32; 3], f32),
        packet: &mut RayPacket16,
        reaches: &mut impl FnMut(&mut RayPacket16) -> u16,
    ) -> u64 {
        self.unique.clear();
        for &i in &self.todo {
            let first = self.first_at[i];
            if !self.traced[first] {
                self.traced[first] = true;
                self.unique.push(first);
            }
        }
        let mut rays = 0;
        for chunk in self.unique.chunks(16) {
            packet.clear();
            for (lane, &i) in chunk.iter().enumerate() {
                let (org, dir, reach) = ray(i);
                packet.set(lane, org, dir, super::RAY_START, reach);
            }
            let active = packet.active_mask();
            if active == 0 {
                continue;
            }
            rays += u64::from(active.count_ones());
            let through = active & reaches(packet);
            for (lane, &i) in chunk.iter().enumerate() {
                self.lit[i] = through & (1 << lane) != 0;
            }
        }
        for &i in &self.todo {
            self.lit[i] = self.lit[self.first_at[i]];
        }
        rays
    }
}

/// Sample `i` needs no ray of its own (`unused` as [`VisibilityScratch`] keeps it).
fn is_unused(unused: &[bool], i: usize) -> bool {
    unused.get(i).copied().unwrap_or(false)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::trace::hulls::tests::luxel_over_edge;
    use proptest::prelude::*;

    proptest! {
        /// Gathered eight at a time, the bits are those of each item in turn.
        #[test]
        fn bits_where_sets_bit_k_for_item_k(values in proptest::collection::vec(
            prop_oneof![Just(0.0f64), Just(-0.0), Just(f64::NAN), -2.0f64..2.0],
            0..=64,
        )) {
            let one_by_one = values
                .iter()
                .enumerate()
                .fold(0u64, |bits, (k, &v)| bits | u64::from(v != 0.0) << k);
            prop_assert_eq!(valued(&values), one_by_one);
        }
    }

    /// Traces the one luxel of `samples` (every sample lit by a light straight above) with
    /// rays blocked where `blocked` says of their origin; returns `lit` and the rays cast.
    fn trace_luxel(samples: &FaceSamples, blocked: fn([f32; 3]) -> bool) -> (Vec<bool>, u64) {
        let mut scratch = VisibilityScratch::default();
        scratch.start_face(samples, false);
        let value = vec![1.0; samples.points.len()];
        let ray = |i: usize| (samples.points[i], [0.0, 0.0, 1.0], 100.0);
        let reaches = |p: &mut RayPacket16| {
            (0..16)
                .filter(|&lane| p.segment(lane).is_some_and(|(org, ..)| !blocked(org)))
                .fold(0u16, |mask, lane| mask | 1 << lane)
        };
        let rays = scratch.trace(samples, true, &value, ray, &mut RayPacket16::new(), reaches);
        (scratch.lit, rays)
    }

    #[test]
    fn a_luxel_over_an_edge_traces_its_hull_corners_when_they_agree() {
        // The probe is moved (onto x = 8): the neighbours cannot answer for the luxel.
        let samples = luxel_over_edge(4, 8.0);
        let (lit, rays) = trace_luxel(&samples, |_| false);
        assert!(lit.iter().all(|&l| l));
        // The probe and the four corners, of twelve places.
        assert_eq!(rays, 5);
    }

    #[test]
    fn a_shadow_edge_between_the_corners_traces_every_sample() {
        let samples = luxel_over_edge(4, 8.0);
        let blocked = |p: [f32; 3]| p[1] > 9.0;
        let (lit, rays) = trace_luxel(&samples, blocked);
        for (i, p) in samples.points.iter().enumerate() {
            assert_eq!(lit[i], !blocked(*p), "sample {i} at {p:?}");
        }
        // Every distinct place once.
        assert_eq!(rays, 12);
    }
}
