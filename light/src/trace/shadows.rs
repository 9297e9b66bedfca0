//! Which samples a light reaches: shadow rays 16 to a packet, samples at one point sharing
//! a ray, and on supersampled faces (or for the many directions of a soft sun) probes first,
//! with the rays between them traced only where the probes disagree.

use crate::embree::RayPacket16;
use crate::grid::SampleGrid;
use crate::samples::FaceSamples;

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
}

impl VisibilityScratch {
    /// Ready for a face whose samples' first-at-the-same-point map is `first_at`.
    pub fn start_face(&mut self, first_at: Vec<usize>) {
        self.first_at = first_at;
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
    /// edges, spots where a probe had no ray) trace every sub-sample. A
    /// straight shadow edge through a luxel always separates its probe from
    /// a neighbour's; only shadows thinner than a luxel can slip between.
    /// Moved samples (see [`FaceSamples::moved`]) are always traced.
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
        if !adaptive || per == 1 {
            self.todo.extend((0..n).filter(|&i| value[i] != 0.0));
            return self.cast(&ray, packet, &mut reaches);
        }
        let axis = samples.per_axis;
        let probe_sub = (axis / 2) * axis + axis / 2;
        let luxels = samples.luxels();
        self.todo.extend(
            (0..luxels)
                .map(|l| l * per + probe_sub)
                .filter(|&i| value[i] != 0.0),
        );
        let mut rays = self.cast(&ray, packet, &mut reaches);
        self.probes.clear();
        self.probes.extend((0..luxels).map(|l| {
            let i = l * per + probe_sub;
            match (value[i] != 0.0, self.lit[i]) {
                (false, _) => Probe::Missing,
                (true, true) => Probe::Reaches,
                (true, false) => Probe::Blocked,
            }
        }));
        self.todo.clear();
        let (w, h) = (samples.width, samples.height);
        for l in 0..luxels {
            let (x, y) = (l % w, l / w);
            let probe = self.probes[l];
            let uniform = !samples.moved[l * per + probe_sub]
                && probe != Probe::Missing
                && (y.saturating_sub(1)..(y + 2).min(h)).all(|ny| {
                    (x.saturating_sub(1)..(x + 2).min(w))
                        .all(|nx| self.probes[ny * w + nx] == probe)
                });
            let first = l * per;
            for (i, &v) in value.iter().enumerate().skip(first).take(per) {
                if v == 0.0 || i == first + probe_sub {
                    continue;
                }
                // Moved points (the luxel overhangs the face, or something
                // rests on it) are off the grid the neighbour test assumes.
                if uniform && !samples.moved[i] {
                    self.lit[i] = probe == Probe::Reaches;
                } else {
                    self.todo.push(i);
                }
            }
        }
        rays += self.cast(&ray, packet, &mut reaches);
        rays
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
        for i in (0..n).filter(|&i| value[i] != 0.0) {
            let (corners, _, _) = grid.cell(i % w, i / w);
            if corners[0] == (i % w, i / w) {
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
