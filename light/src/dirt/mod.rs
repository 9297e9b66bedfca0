//! Dirt: ambient occlusion after q3map2 and ericw-tools, how enclosed each sample point is.
//!
//! A sample casts [`rays::RAYS_PER_SAMPLE`] rays into the cone of `_dirtangle` degrees around its
//! shading normal (the `_phong` one on smoothed faces), up to `_dirtdepth` units ([`rays`]):
//! `_dirtmode 0` spreads them over the same rings and azimuths for every sample, `1` at
//! directions drawn per sample from a hash of face and sample, so results do not depend on
//! threads. Its occlusion is the mean over its rays of `1 - hit distance / depth` (a ray that
//! meets nothing opaque within the depth, or meets sky, adds 0). A light, sun or minlight that
//! takes dirt is multiplied by [`DirtResponse::factor`] of it.
//!
//! Occlusion is measured after the shadow rays, only at samples some light that takes dirt
//! reaches, and only at the corners of cells where it is smooth ([`adaptive`]); [`DirtFactors`]
//! turns it into each response's factor once per face.

mod adaptive;
mod rays;

pub use adaptive::{DirtNeed, FaceDirt, face_occlusion};
pub use rays::{ConePattern, ordered_components};
#[cfg(test)]
pub use rays::{DirtRays, occlusion_at};

/// How dirt (ambient occlusion) darkens one light: ericw-tools' `_dirtscale`
/// and `_dirtgain`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirtResponse {
    /// `_dirtscale`: how strongly occlusion darkens.
    pub scale: f64,
    /// `_dirtgain`: the exponent on occlusion.
    pub gain: f64,
}

impl DirtResponse {
    /// Multiplier for light reaching a point with `occlusion` (0 = open,
    /// 1 = every dirt ray hit something right away): `1 - min(1, scale *
    /// min(1, occlusion^gain))`.
    pub fn factor(&self, occlusion: f64) -> f64 {
        if occlusion <= 0.0 {
            return 1.0;
        }
        let dirt = (occlusion.powf(self.gain).min(1.0) * self.scale).min(1.0);
        1.0 - dirt
    }
}

/// How dirt rays are spread over the cone around a sample's normal (`_dirtmode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DirtMode {
    /// 0: the same evenly spaced directions for every sample.
    Ordered,
    /// 1: different pseudo-random directions per sample (deterministic).
    Random,
}

/// How occlusion is measured: worldspawn `_dirtmode`, `_dirtdepth`, `_dirtangle`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DirtSampling {
    /// How rays spread over the cone.
    pub mode: DirtMode,
    /// Rays longer than this see no occluder.
    pub depth: f64,
    /// Angle from the normal of the outermost rays, in degrees (1..=90).
    cone_degrees: f64,
    /// The ordered pattern for this cone in a face's own terms, worked out once: its sines and
    /// cosines are the same for every face.
    ordered: ConePattern,
}

impl DirtSampling {
    /// Rays of `mode` up to `depth` units long, in a cone of `cone_degrees` from the normal.
    pub fn new(mode: DirtMode, depth: f64, cone_degrees: f64) -> DirtSampling {
        DirtSampling {
            mode,
            depth,
            cone_degrees,
            ordered: ordered_components(cone_degrees.to_radians()),
        }
    }

    /// Angle from the normal of the outermost rays, in degrees.
    pub fn cone_degrees(&self) -> f64 {
        self.cone_degrees
    }

    pub fn ordered(&self) -> &ConePattern {
        &self.ordered
    }
}

/// Dirt factors per sample, computed once per distinct [`DirtResponse`]
/// (a face sees few of them; `powf` per sample and light is not cheap).
pub struct DirtFactors<'a> {
    occlusion: &'a [f32],
    computed: Vec<(DirtResponse, Vec<f32>)>,
}

impl<'a> DirtFactors<'a> {
    /// `occlusion` per sample, or empty when the face takes no dirt.
    pub fn new(occlusion: &'a [f32], samples: usize) -> DirtFactors<'a> {
        let occlusion = if occlusion.len() == samples {
            occlusion
        } else {
            &[]
        };
        DirtFactors {
            occlusion,
            computed: Vec::new(),
        }
    }

    /// The factor per sample for `response`; `None` means 1 everywhere.
    pub fn get(&mut self, response: Option<DirtResponse>) -> Option<&[f32]> {
        let r = response.filter(|_| !self.occlusion.is_empty())?;
        let k = match self.computed.iter().position(|(c, _)| *c == r) {
            Some(k) => k,
            None => {
                let f = self
                    .occlusion
                    .iter()
                    .map(|&o| r.factor(f64::from(o)) as f32)
                    .collect();
                self.computed.push((r, f));
                self.computed.len() - 1
            }
        };
        Some(&self.computed[k].1)
    }
}
