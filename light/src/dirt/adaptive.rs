//! Where a face's occlusion is measured and where it is interpolated.
//!
//! Occlusion changes slowly across open floor and fast at corners and under objects, so it is
//! measured first at the corners of coarse cells ([`DIRT_COARSE_CELLS`] fine cells wide), then
//! at the corners of the fine cells (every `stride`-th sample along each axis of the face's
//! sample grid: one per luxel when supersampling, every other luxel otherwise), both grids
//! with the face's last row and column. A sample whose cell corners agree to within
//! [`DIRT_SMOOTH`] (or [`DIRT_SMOOTH_SUPERSAMPLED`]) takes their bilinear mean, first in the
//! coarse cell, else in the fine one; so does one whose fine corners the coarse cell predicts
//! to within as much (a steady slope away from a wall). The others (corners, edges of
//! objects) are measured, as is every sample that stands apart: on the face's edge or nudged
//! out of solid ([`FaceSamples::apart`]), and when supersampling every moved one (a luxel's
//! sub-samples are close together).
//!
//! Only samples some light that takes dirt reaches need a value ([`DirtNeed`]), and a needed
//! sample's value never depends on which others are needed: interpolation reads measured
//! corners only. Where only bounced light takes dirt (faint and smooth), supersampled faces
//! interpolate in the fine cell whatever its corners' spread, and measured samples cast half
//! the rays.

use super::rays::{DirtRays, occlusion_at};
use super::{DirtMode, DirtSampling};
use crate::grid::SampleGrid;
use crate::samples::FaceSamples;
use crate::scene::TraceScene;

/// Occlusion may be interpolated between grid points that differ by at most this much (a
/// light's dirt factor then moves by about as much). Lower values cast more rays in the
/// default mode for no error a lightmap byte shows.
const DIRT_SMOOTH: f32 = 0.1;

/// [`DIRT_SMOOTH`] when supersampling, whose error against the reference is small enough for
/// the interpolation's to show.
const DIRT_SMOOTH_SUPERSAMPLED: f32 = 0.01;

/// Coarse dirt cells are this many fine cells wide: occlusion is first
/// measured on the coarse grid, and cells whose corners differ are refined.
const DIRT_COARSE_CELLS: usize = 2;

/// Why a sample's dirt occlusion is wanted.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirtNeed {
    /// Nothing that takes dirt reaches the sample.
    No,
    /// Only bounced light (which is smooth and faint where no light reaches) takes it.
    Bounce,
    /// A light, sun or minlight that takes dirt reaches the sample.
    Light,
}

/// What the occlusion of one face is measured with.
#[derive(Clone, Copy)]
pub struct FaceDirt<'a> {
    /// The scene dirt rays are traced in.
    pub scene: &'a TraceScene,
    /// The face's samples.
    pub samples: &'a FaceSamples,
    /// The face's brush model (for `_shadowself` scenes).
    pub model: usize,
    /// The face's light channels (dirt comes from what shares one).
    pub channels: u32,
    /// The ray pattern, its depth and cone.
    pub sampling: &'a DirtSampling,
    /// Per sample, the first sample at the same point ([`FaceSamples::first_at_same_point`]).
    pub first_at: &'a [usize],
    /// Per sample, why its occlusion is wanted.
    pub needed: &'a [DirtNeed],
}

/// Dirt occlusion of every sample of a face (see [`occlusion_at`]) marked in `dirt.needed`
/// (the others 0), and the rays cast: every needed sample measured, or with `adaptive` (every
/// mode but the reference) measured or interpolated as the module comment says.
pub fn face_occlusion(dirt: FaceDirt, adaptive: bool) -> (Vec<f32>, u64) {
    let mut measured = Measured {
        dirt,
        adaptive,
        known: vec![None; dirt.samples.points.len()],
        rays: 0,
    };
    if adaptive {
        Adaptive::new(dirt).measure(&mut measured);
    } else {
        let mut all: Vec<usize> = (0..dirt.needed.len())
            .filter(|&i| dirt.needed[i] != DirtNeed::No)
            .collect();
        measured.measure(&mut all);
    }
    let values = measured.known.into_iter().map(|v| v.unwrap_or(0.0));
    (values.collect(), measured.rays)
}

/// A face's occlusion as far as it is measured, and the rays cast for it.
struct Measured<'a> {
    dirt: FaceDirt<'a>,
    adaptive: bool,
    known: Vec<Option<f32>>,
    rays: u64,
}

impl Measured<'_> {
    /// The occlusion at `indices` with `which` of their rays, and the rays cast. Ordered dirt
    /// rays depend only on the point, so samples at one point share them.
    fn occlusion(&self, indices: &[usize], which: DirtRays) -> (Vec<f32>, u64) {
        let d = &self.dirt;
        if d.sampling.mode != DirtMode::Ordered {
            return occlusion_at(
                d.samples,
                indices,
                (d.model, d.channels),
                d.sampling,
                which,
                d.scene,
            );
        }
        let mut unique: Vec<usize> = indices.iter().map(|&i| d.first_at[i]).collect();
        unique.sort_unstable();
        unique.dedup();
        let (values, rays) = occlusion_at(
            d.samples,
            &unique,
            (d.model, d.channels),
            d.sampling,
            which,
            d.scene,
        );
        let value_of = |i: usize| {
            unique
                .binary_search(&d.first_at[i])
                .map_or(0.0, |k| values[k])
        };
        (indices.iter().map(|&i| value_of(i)).collect(), rays)
    }

    /// Measures the samples `indices` (sorted and deduplicated first) into `known`. Samples
    /// only bounced light takes dirt at cast half the rays (the adaptive modes).
    fn measure(&mut self, indices: &mut Vec<usize>) {
        indices.sort_unstable();
        indices.dedup();
        let (half, all): (Vec<usize>, Vec<usize>) = indices
            .iter()
            .partition(|&&i| self.adaptive && self.dirt.needed[i] == DirtNeed::Bounce);
        for (group, which) in [(all, DirtRays::All), (half, DirtRays::Half)] {
            if group.is_empty() {
                continue;
            }
            let (values, rays) = self.occlusion(&group, which);
            self.rays += rays;
            for (&i, v) in group.iter().zip(values) {
                self.known[i] = Some(v);
            }
        }
    }
}

/// A face's samples as a grid of `gw × gh` positions (`axis` samples per luxel along each axis),
/// and the two grids of cell corners occlusion is measured at.
struct Adaptive<'a> {
    samples: &'a FaceSamples,
    needed: &'a [DirtNeed],
    axis: usize,
    coarse: SampleGrid,
    fine: SampleGrid,
    /// Corners that differ by at most this much are interpolated between.
    smooth: f32,
}

impl<'a> Adaptive<'a> {
    fn new(dirt: FaceDirt<'a>) -> Adaptive<'a> {
        let samples = dirt.samples;
        let axis = samples.per_axis;
        let stride = axis.max(2);
        let (gw, gh) = (samples.width * axis, samples.height * axis);
        Adaptive {
            samples,
            needed: dirt.needed,
            axis,
            coarse: SampleGrid::new(gw, gh, stride * DIRT_COARSE_CELLS),
            fine: SampleGrid::new(gw, gh, stride),
            smooth: if axis > 1 {
                DIRT_SMOOTH_SUPERSAMPLED
            } else {
                DIRT_SMOOTH
            },
        }
    }

    fn supersampled(&self) -> bool {
        self.axis > 1
    }

    /// The sample index of grid position (gx, gy).
    fn index(&self, (gx, gy): (usize, usize)) -> usize {
        let axis = self.axis;
        ((gy / axis) * self.samples.width + gx / axis) * axis * axis
            + (gy % axis) * axis
            + gx % axis
    }

    /// Whether sample `i` is needed for bounced light alone on a supersampled face (where the
    /// fine cell's mean will do whatever its corners' spread).
    fn bounce_only(&self, i: usize) -> bool {
        self.needed[i] == DirtNeed::Bounce && self.supersampled()
    }

    /// Measures or interpolates every needed sample into `m`.
    fn measure(&self, m: &mut Measured) {
        let (mut pending, mut batch) = self.on_and_off_grid();
        let mut interpolated: Vec<(usize, f32)> = Vec::new();
        for (grid, outer) in [(&self.coarse, None), (&self.fine, Some(&self.coarse))] {
            // The corners of the cells of the samples still pending (a sample on the grid is
            // its own first corner), then what they let us interpolate.
            for &(gx, gy) in &pending {
                let (corners, _, _) = grid.cell(gx, gy);
                batch.extend(
                    corners
                        .map(|c| self.index(c))
                        .into_iter()
                        .filter(|&c| m.known[c].is_none()),
                );
            }
            m.measure(&mut batch);
            batch.clear();
            pending.retain(|&at| match self.interpolate(&m.known, grid, outer, at) {
                Some(value) => {
                    interpolated.push((self.index(at), value));
                    false
                }
                None => m.known[self.index(at)].is_none(),
            });
        }
        batch.extend(pending.iter().map(|&p| self.index(p)));
        m.measure(&mut batch);
        for (i, v) in interpolated {
            m.known[i] = Some(v);
        }
    }

    /// The needed samples on the grid (by position), to measure at cell corners or interpolate,
    /// and those off it (by index), to measure.
    fn on_and_off_grid(&self) -> (Vec<(usize, usize)>, Vec<usize>) {
        let (mut on, mut off) = (Vec::new(), Vec::new());
        let (gw, gh) = (
            self.samples.width * self.axis,
            self.samples.height * self.axis,
        );
        for gy in 0..gh {
            for gx in 0..gw {
                let i = self.index((gx, gy));
                if self.needed[i] == DirtNeed::No {
                    continue;
                }
                let off_grid = if self.supersampled() {
                    self.samples.moved[i]
                } else {
                    self.samples.apart[i]
                };
                if off_grid && !self.bounce_only(i) {
                    off.push(i);
                } else {
                    on.push((gx, gy));
                }
            }
        }
        (on, off)
    }

    /// The interpolated occlusion at `at` in its cell of `grid`, when it may be interpolated
    /// there (`None` also when it is measured already). `outer` is the coarser grid, whose
    /// cells may vouch for a fine cell whose corners differ.
    fn interpolate(
        &self,
        known: &[Option<f32>],
        grid: &SampleGrid,
        outer: Option<&SampleGrid>,
        at: (usize, usize),
    ) -> Option<f32> {
        if known[self.index(at)].is_some() {
            return None;
        }
        let bounce_only = self.bounce_only(self.index(at));
        if bounce_only && outer.is_none() {
            return None; // the fine cell's corners are measured next
        }
        let (value, spread) = self.bilinear(known, grid, at)?;
        // Corners that differ may still be interpolated between where the occlusion is close
        // to bilinear: the coarse cell's mean predicts each of them to within `smooth`.
        let linear = || {
            let Some(outer) = outer else {
                return false;
            };
            grid.cell(at.0, at.1).0.iter().all(|&c| {
                let measured = known[self.index(c)];
                let predicted = self.bilinear(known, outer, c);
                matches!((measured, predicted), (Some(m), Some((p, _))) if (m - p).abs() <= self.smooth)
            })
        };
        (bounce_only || spread <= self.smooth || linear()).then_some(value)
    }

    /// The bilinear mean at `at` of its cell's corners in `grid` and how much they differ,
    /// when all four are measured (only measured values: a needed sample's value must not
    /// depend on which others are needed) and none stands apart ([`FaceSamples::apart`]).
    fn bilinear(
        &self,
        known: &[Option<f32>],
        grid: &SampleGrid,
        (gx, gy): (usize, usize),
    ) -> Option<(f32, f32)> {
        let (corners, fx, fy) = grid.cell(gx, gy);
        let values = corners.map(|c| {
            let c = self.index(c);
            known[c].filter(|_| !self.samples.apart[c])
        });
        let [Some(a), Some(b), Some(c), Some(d)] = values else {
            return None;
        };
        let top = a + (b - a) * fx;
        let bottom = c + (d - c) * fx;
        let spread = a.max(b).max(c).max(d) - a.min(b).min(c).min(d);
        Some((top + (bottom - top) * fy, spread))
    }
}
