//! A face's light per sample and style, as tracing leaves it: sums, local-minlight floors,
//! `--addmin` minlight, the dirt factor of bounced light and (for deluxemaps) the directions
//! light arrived from, until [`SampleLight::finish`] adds bounce, applies the floors and
//! averages samples to luxels.

use glam::{DMat3, DVec3, Vec3};

use super::FaceLight;
use crate::luxels::{ToLuxels, ericw_luxels};

/// Per-sample buffers, one per style (style 0 always present and first).
#[derive(Debug)]
pub struct StyleBuffers {
    pub len: usize,
    pub styles: Vec<(u8, Vec<[f32; 3]>)>,
}

impl StyleBuffers {
    pub fn new(len: usize) -> StyleBuffers {
        StyleBuffers {
            len,
            styles: vec![(0, vec![[0.0; 3]; len])],
        }
    }

    /// No style yet: [`StyleBuffers::get`] makes each when first asked for.
    pub fn none_yet(len: usize) -> StyleBuffers {
        StyleBuffers {
            len,
            styles: Vec::new(),
        }
    }

    pub fn get(&mut self, style: u8) -> &mut Vec<[f32; 3]> {
        let len = self.len;
        crate::styles::entry(&mut self.styles, style, || vec![[0.0; 3]; len])
    }
}

/// A face's light per sample before minlight floors are applied, so that
/// bounced light can still be added (floors apply to the sum).
#[derive(Debug)]
pub struct SampleLight {
    pub face: usize,
    pub width: usize,
    pub height: usize,
    pub(super) per_luxel: usize,
    pub(super) sums: StyleBuffers,
    /// Per style, the floor under its sums (style 0's is zero until something raises it).
    pub(super) floors: StyleBuffers,
    /// `--addmin` minlight of style 0, added when finishing (it does not bounce).
    pub(super) added_minlight: Option<Vec<[f32; 3]>>,
    /// The part of `sums` that does not bounce (`_bounce 0` lights, the rest of a
    /// `_bouncescale`).
    pub(super) no_bounce: Option<StyleBuffers>,
    /// Per sample, the dirt factor of bounced light (empty: none).
    pub(super) bounce_dirt: Vec<f32>,
    /// Where light came from, when deluxemaps are wanted.
    pub(super) directions: Option<Directions>,
    /// Per sample, inside solid: left out of its luxel's mean (empty: none is).
    pub(super) occluded: Vec<bool>,
    /// The brightest channel a sample may reach (`_maxlight`); a brighter one is scaled down.
    pub(super) max_sample: Option<f32>,
    /// `_lightcolorscale` ([`super::FaceRules::color_scale`]).
    pub(super) color_scale: Option<f32>,
}

/// Per sample and style, the directions towards the lights and suns that reached it, each
/// weighted by the light it brought; and the face's tangent space, in which a luxel's mean
/// direction is given (deluxemaps).
#[derive(Debug)]
pub struct Directions {
    /// The sample points, for the direction to a point light.
    points: Vec<[f32; 3]>,
    sums: StyleBuffers,
    /// Rows: the face's texture s direction, the direction of decreasing t, and its normal (all
    /// unit), as ericw-tools, FTE and DarkPlaces read deluxemaps.
    to_tangent: DMat3,
}

impl Directions {
    /// Directions of light arriving at `points`, on a face with texture projection `vecs` and
    /// outward `normal`.
    pub fn new(points: &[[f32; 3]], vecs: &[[f32; 4]; 2], normal: DVec3) -> Directions {
        let axis = |v: [f32; 4]| Vec3::new(v[0], v[1], v[2]).as_dvec3().normalize_or_zero();
        let (s, t) = (axis(vecs[0]), -axis(vecs[1]));
        Directions {
            points: points.to_vec(),
            sums: StyleBuffers::new(points.len()),
            to_tangent: DMat3::from_cols(s, t, normal).transpose(),
        }
    }

    /// Light of `weight` reached sample `i` in `style` from direction `to_light` (unit).
    fn add(&mut self, style: u8, i: usize, to_light: DVec3, weight: f64) {
        let sum = &mut self.sums.get(style)[i];
        for (o, d) in sum.iter_mut().zip(to_light.to_array()) {
            *o += (d * weight) as f32;
        }
    }

    /// Light of `weight` reached sample `i` in `style` from a light at `origin`.
    pub(super) fn add_from_point(&mut self, style: u8, i: usize, origin: DVec3, weight: f64) {
        let to_light = origin - Vec3::from(self.points[i]).as_dvec3();
        self.add(style, i, to_light.normalize_or_zero(), weight);
    }

    /// Light of `weight` reached sample `i` in `style` from a sun in direction `to_sun`.
    pub(super) fn add_from_sun(&mut self, style: u8, i: usize, to_sun: DVec3, weight: f64) {
        self.add(style, i, to_sun, weight);
    }

    /// Per style, each luxel's mean direction in tangent space (unit; zero where no light
    /// with a direction arrived), `per` samples to a luxel.
    fn luxel_directions(self, per: usize) -> Vec<(u8, Vec<[f32; 3]>)> {
        let to_tangent = self.to_tangent;
        self.sums
            .styles
            .into_iter()
            .map(|(style, sums)| {
                let luxels = sums
                    .chunks(per)
                    .map(|c| {
                        let sum = c
                            .iter()
                            .fold(DVec3::ZERO, |a, v| a + Vec3::from(*v).as_dvec3());
                        (to_tangent * sum).normalize_or_zero().as_vec3().to_array()
                    })
                    .collect();
                (style, luxels)
            })
            .collect()
    }
}

/// Luxel means of per-sample values, `per` samples to a luxel (one sample to a luxel, as in
/// the default mode: the values themselves, not copied).
fn luxel_means(values: Vec<[f32; 3]>, per: usize) -> Vec<[f32; 3]> {
    if per == 1 {
        return values;
    }
    values
        .chunks(per)
        .map(|c| {
            let mut acc = [0.0f32; 3];
            for v in c {
                for k in 0..3 {
                    acc[k] += v[k];
                }
            }
            acc.map(|a| a / per as f32)
        })
        .collect()
}

/// What a luxel whose every sample is occluded takes when its face is finished.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HiddenLuxels {
    /// Its neighbours' light, as [`ToLuxels`] fills it (ericw-tools fills a world face's so);
    /// a face with every sample occluded keeps the means of all of them (a world face's: its
    /// minlight alone, as no light reaches a sample inside solid).
    FromNeighbours,
    /// Nothing yet (zero): a brush model's are filled from the whole model afterwards.
    Later,
    /// Nothing: an occluded sample adds no light to its luxel, which takes the sum of its open
    /// samples over all of them (with `--reference`, the mean of its open samples). A
    /// shadow-casting brush model's, as ericw-tools leaves them: its faces in the world's
    /// solid stay dark.
    Dark,
}

/// Luxel means of per-sample values over the samples not `occluded`; a luxel with none is
/// filled as `hidden` says.
fn open_luxel_means(
    values: Vec<[f32; 3]>,
    per: usize,
    occluded: &[bool],
    width: usize,
    hidden: HiddenLuxels,
) -> Vec<[f32; 3]> {
    if !occluded.contains(&true)
        || (hidden == HiddenLuxels::FromNeighbours && occluded.iter().all(|&o| o))
    {
        return luxel_means(values, per);
    }
    let mut luxels: Vec<Option<[f32; 3]>> = values
        .chunks(per)
        .zip(occluded.chunks(per))
        .map(|(v, o)| {
            let open: Vec<&[f32; 3]> = v
                .iter()
                .zip(o)
                .filter(|(_, o)| !**o)
                .map(|(v, _)| v)
                .collect();
            (!open.is_empty()).then(|| {
                let mut acc = [0.0f32; 3];
                for v in &open {
                    for k in 0..3 {
                        acc[k] += v[k];
                    }
                }
                acc.map(|a| a / open.len() as f32)
            })
        })
        .collect();
    if hidden != HiddenLuxels::FromNeighbours {
        return luxels.into_iter().map(Option::unwrap_or_default).collect();
    }
    let height = luxels.len() / width.max(1);
    while luxels.contains(&None) {
        let before = luxels.clone();
        for (i, luxel) in luxels.iter_mut().enumerate().filter(|(_, l)| l.is_none()) {
            let (x, y) = (i % width, i / width);
            let mut acc = [0.0f32; 3];
            let mut count = 0.0f32;
            for ny in y.saturating_sub(1)..(y + 2).min(height) {
                for nx in x.saturating_sub(1)..(x + 2).min(width) {
                    if let Some(v) = before[ny * width + nx] {
                        for k in 0..3 {
                            acc[k] += v[k];
                        }
                        count += 1.0;
                    }
                }
            }
            if count > 0.0 {
                *luxel = Some(acc.map(|a| a / count));
            }
        }
    }
    luxels.into_iter().flatten().collect()
}

impl SampleLight {
    /// Whether any sample is inside solid.
    pub fn has_occluded(&self) -> bool {
        self.occluded.contains(&true)
    }

    /// Per luxel, whether its every sample is inside solid (empty when no sample is).
    pub fn hidden_luxels(&self) -> Vec<bool> {
        if !self.has_occluded() {
            return Vec::new();
        }
        self.occluded
            .chunks(self.per_luxel)
            .map(|o| o.iter().all(|&o| o))
            .collect()
    }

    /// ericw-tools' "autominlight" for a brush model's face: every occluded sample takes
    /// `light` (the model's light per style, nothing of the face's other styles) and counts as
    /// open from here on; with `everywhere`, every other sample is raised to it too. Floors
    /// still raise them.
    pub fn with_model_light(mut self, light: &[(u8, [f32; 3])], everywhere: bool) -> SampleLight {
        if !everywhere && !self.has_occluded() {
            return self;
        }
        for &(style, _) in light {
            self.sums.get(style);
        }
        for (style, values) in &mut self.sums.styles {
            let value = light
                .iter()
                .find(|(s, _)| s == style)
                .map_or([0.0; 3], |&(_, c)| c);
            for (i, v) in values.iter_mut().enumerate() {
                if self.occluded.get(i).copied().unwrap_or(false) {
                    *v = value;
                } else if everywhere {
                    *v = std::array::from_fn(|k| v[k].max(value[k]));
                }
            }
        }
        self.occluded.clear();
        self
    }

    /// Per style, the luxel means of the light that reflects: lights and
    /// suns without minlight, each light's times its `_bouncescale` (0 for
    /// `_bounce 0`); style 0 only unless `styled`. Styles with no light are left out.
    pub fn reflected(&self, styled: bool) -> Vec<(u8, Vec<[f32; 3]>)> {
        let mut out = Vec::new();
        for (style, values) in &self.sums.styles {
            if *style != 0 && !styled {
                continue;
            }
            let mut values = values.clone();
            if let Some(no) = &self.no_bounce
                && let Some((_, minus)) = no.styles.iter().find(|(s, _)| s == style)
            {
                for (v, m) in values.iter_mut().zip(minus) {
                    for k in 0..3 {
                        v[k] = (v[k] - m[k]).max(0.0);
                    }
                }
            }
            if values.iter().any(|v| v.iter().any(|&c| c > 0.0)) {
                out.push((*style, luxel_means(values, self.per_luxel)));
            }
        }
        out
    }

    /// Per luxel, the share of the bounced light it receives that it sends on to the next pass:
    /// the mean over its samples of the dirt factor, a sample inside solid counting 0, as
    /// ericw-tools' faces pass on the bounced light their open samples show. `None` when every
    /// luxel passes on all of it.
    pub fn passed_on(&self) -> Option<Vec<f32>> {
        if self.bounce_dirt.is_empty() && !self.has_occluded() {
            return None;
        }
        let samples = self.width * self.height * self.per_luxel;
        let share = |i: usize| {
            if self.occluded.get(i).copied().unwrap_or(false) {
                0.0
            } else {
                self.bounce_dirt.get(i).copied().unwrap_or(1.0)
            }
        };
        let per = self.per_luxel.max(1);
        Some(
            (0..samples)
                .step_by(per)
                .map(|first| (first..first + per).map(share).sum::<f32>() / per as f32)
                .collect(),
        )
    }

    /// Adds `bounce` (per style, per luxel (given to each of the luxel's
    /// samples not inside solid) or per sample, times each sample's dirt factor), applies
    /// minlight and the floors, and turns samples into luxels as `to_luxels` says, filling
    /// luxels whose every sample is occluded as `hidden` says.
    pub fn finish(
        mut self,
        bounce: &[(u8, Vec<[f32; 3]>)],
        hidden: HiddenLuxels,
        to_luxels: ToLuxels,
    ) -> FaceLight {
        let per = self.per_luxel;
        if let Some(min) = &self.added_minlight {
            for (s, m) in self.sums.get(0).iter_mut().zip(min) {
                for k in 0..3 {
                    s[k] += m[k];
                }
            }
        }
        for (style, luxels) in bounce {
            let dirt = &self.bounce_dirt;
            let sums = self.sums.get(*style);
            let step = if luxels.len() == sums.len() { 1 } else { per };
            for (i, s) in sums.iter_mut().enumerate() {
                // Bounced light reaches no sample inside solid (as lights and suns do not).
                let Some(b) = luxels
                    .get(i / step)
                    .filter(|_| !self.occluded.get(i).copied().unwrap_or(false))
                else {
                    continue;
                };
                let f = dirt.get(i).copied().unwrap_or(1.0);
                for k in 0..3 {
                    s[k] += b[k] * f;
                }
            }
        }
        // Style 0's floor is zero where nothing raised it: light never sums below none.
        if !self.floors.styles.iter().any(|(style, _)| *style == 0) {
            for s in self.sums.get(0).as_flattened_mut() {
                *s = s.max(0.0);
            }
        }
        for (style, floor) in &self.floors.styles {
            let sum = self.sums.get(*style);
            for (s, f) in sum.iter_mut().zip(floor) {
                for c in 0..3 {
                    s[c] = s[c].max(f[c]);
                }
            }
        }
        if let Some(cap) = self.max_sample {
            for (_, values) in &mut self.sums.styles {
                for v in values.iter_mut() {
                    let brightest = v[0].max(v[1]).max(v[2]);
                    if brightest > cap {
                        *v = v.map(|c| c * cap / brightest);
                    }
                }
            }
        }
        // `_lightcolorscale`, after the cap as in ericw-tools: toward the brightest channel.
        if let Some(scale) = self.color_scale {
            for (_, values) in &mut self.sums.styles {
                for v in values.iter_mut() {
                    let grey = v[0].max(v[1]).max(v[2]);
                    *v = v.map(|c| grey * (1.0 - scale) + c * scale);
                }
            }
        }
        let (occluded, width) = (&self.occluded, self.width);
        let per_axis = per.isqrt();
        let styles = self
            .sums
            .styles
            .into_iter()
            .map(|(style, mut values)| {
                let means = match (to_luxels, hidden) {
                    (ToLuxels::AsEricw { soft_radius }, HiddenLuxels::FromNeighbours)
                        if soft_radius > 0 || occluded.contains(&true) =>
                    {
                        ericw_luxels(&values, occluded, width, per_axis, soft_radius)
                    }
                    (ToLuxels::AsEricw { soft_radius }, HiddenLuxels::Dark) => {
                        for (v, _) in values.iter_mut().zip(occluded).filter(|(_, o)| **o) {
                            *v = [0.0; 3];
                        }
                        if soft_radius > 0 {
                            ericw_luxels(&values, &[], width, per_axis, soft_radius)
                        } else {
                            luxel_means(values, per)
                        }
                    }
                    _ => open_luxel_means(values, per, occluded, width, hidden),
                };
                (style, means)
            })
            .collect();
        FaceLight {
            face: self.face,
            width: self.width,
            height: self.height,
            styles,
            directions: self
                .directions
                .map_or_else(Vec::new, |d| d.luxel_directions(per)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two luxels of 2 × 2 samples each (samples of a luxel are consecutive).
    fn two_luxels(bounce_dirt: Vec<f32>, occluded: Vec<bool>) -> SampleLight {
        SampleLight {
            face: 0,
            width: 2,
            height: 1,
            per_luxel: 4,
            sums: StyleBuffers::new(8),
            floors: StyleBuffers::none_yet(8),
            added_minlight: None,
            no_bounce: None,
            bounce_dirt,
            directions: None,
            occluded,
            max_sample: None,
            color_scale: None,
        }
    }

    #[test]
    fn a_luxel_passes_on_the_bounce_its_open_samples_show_after_dirt() {
        assert_eq!(two_luxels(Vec::new(), vec![false; 8]).passed_on(), None);
        let open = vec![false; 8];
        let dirt = vec![1.0, 0.5, 1.0, 0.5, 0.25, 0.25, 0.25, 0.25];
        assert_eq!(
            two_luxels(dirt.clone(), open).passed_on(),
            Some(vec![0.75, 0.25])
        );
        // A sample inside solid passes on nothing, with or without dirt.
        let mut solid = vec![false; 8];
        solid[0] = true;
        solid[5] = true;
        assert_eq!(
            two_luxels(Vec::new(), solid.clone()).passed_on(),
            Some(vec![0.75, 0.75])
        );
        assert_eq!(two_luxels(dirt, solid).passed_on(), Some(vec![0.5, 0.1875]));
    }
}
