//! A light at a point and the formulas that turn it and a distance into brightness: falloff
//! (`delay`), the spotlight cone, the angle of incidence, and `_deviance` copies.
//!
//! Brightness is kept in light units (a `light 300` entity gives 300 at its origin with
//! linear falloff); the range scale (`_range`) maps light units to lightmap bytes at the very
//! end.

use std::sync::Arc;

use glam::DVec3;

use super::projection::Projector;
use crate::directions::ball_points;
use crate::dirt::DirtResponse;

/// Distance (map units) at which the 1/x and 1/x² formulas give `light`.
const FALLOFF_SCALE: f64 = 128.0;

/// How brightness falls off with distance (the `delay` key).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Falloff {
    /// 0: `light - dist * wait`.
    Linear,
    /// 1: `light * 128 / (dist * wait)`.
    Inverse,
    /// 2: `light * 128² / (dist * wait)²` (brighter than `light` within 128 units).
    InverseSquare,
    /// 3: `light` at any distance.
    Constant,
    /// 4: "local minlight": raises what the light sees to `light`, never adds.
    LocalMin,
    /// 5: `light * 128² / (dist * wait + 128)²`: inverse square without the
    /// bright spot near the source.
    InverseSquareSoft,
}

impl Falloff {
    pub fn from_delay(delay: i64) -> Option<Falloff> {
        Some(match delay {
            0 => Falloff::Linear,
            1 => Falloff::Inverse,
            2 => Falloff::InverseSquare,
            3 => Falloff::Constant,
            4 => Falloff::LocalMin,
            5 => Falloff::InverseSquareSoft,
            _ => return None,
        })
    }
}

/// A spotlight's cone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Spot {
    /// Unit direction the light shines in.
    pub dir: DVec3,
    /// Cosine of half the outer cone angle: dimmer than this is dark.
    pub cos_outer: f64,
    /// Cosine of half the inner (`_softangle`) cone: full brightness inside.
    pub cos_inner: f64,
}

impl Spot {
    /// A cone of full angle `angle` degrees (non-positive means the default
    /// 40) with an optional soft inner cone of `softangle` degrees.
    pub fn new(dir: DVec3, angle: f64, softangle: f64) -> Spot {
        let angle = if angle > 0.0 {
            angle.min(360.0)
        } else {
            DEFAULT_SPOT_ANGLE
        };
        let cos_outer = (angle.to_radians() / 2.0).cos();
        let cos_inner = if softangle > 0.0 && softangle < angle {
            (softangle.to_radians() / 2.0).cos()
        } else {
            cos_outer
        };
        Spot {
            dir,
            cos_outer,
            cos_inner,
        }
    }

    /// Brightness factor for a point in unit direction `to_point` from the
    /// light: 1 inside the inner cone, 0 outside the outer one, linear in the
    /// cosine between them.
    pub fn factor(&self, to_point: DVec3) -> f64 {
        let c = self.dir.dot(to_point);
        if c < self.cos_outer {
            0.0
        } else if c >= self.cos_inner {
            1.0
        } else {
            (c - self.cos_outer) / (self.cos_inner - self.cos_outer)
        }
    }
}

/// The angle-of-incidence term: `scale * cos + (1 - scale)` for a surface
/// facing the light or grazed by it (`cos >= 0`, as in ericw-tools: a light level with the
/// samples still lights them), else 0.
pub fn angle_factor(cos_incidence: f64, anglescale: f64) -> f64 {
    let facing = anglescale * cos_incidence + (1.0 - anglescale);
    if cos_incidence < 0.0 { 0.0 } else { facing }
}

/// A light at a point (an entity, or one copy of a `_surface` template).
#[derive(Debug, Clone, PartialEq)]
pub struct PointLight {
    pub origin: DVec3,
    /// Brightness in light units; negative lights subtract.
    pub light: f64,
    /// Distance scale of the falloff: `wait` times the global `_dist`.
    pub atten: f64,
    pub falloff: Falloff,
    /// Per-channel colour, 1.0 = white.
    pub color: DVec3,
    pub style: u8,
    pub spot: Option<Spot>,
    pub anglescale: f64,
    /// How dirt darkens this light (`None`: it ignores dirt).
    pub dirt: Option<DirtResponse>,
    /// How much of its light bounces: `_bouncescale` (0 for `_bounce 0`).
    pub bounce: f32,
    /// The light channels it lights (`_light_channel_mask`): the faces of models whose
    /// channels share a bit with these.
    pub light_channels: u32,
    /// The light channels whose models block its rays (`_shadow_channel_mask`).
    pub shadow_channels: u32,
    /// Entity index it came from (for messages).
    pub entity: usize,
    /// The picture it projects (`_project_texture`), which tints its colour point by point.
    pub projector: Option<Arc<Projector>>,
}

impl PointLight {
    /// The light's colour at `point`: its own, tinted by the picture it projects there.
    pub fn color_at(&self, point: DVec3) -> DVec3 {
        match &self.projector {
            None => self.color,
            Some(p) => self.color * p.tint(point),
        }
    }

    /// Brightness at `dist` units from the light before angle and cone terms.
    pub fn value_at(&self, dist: f64) -> f64 {
        self.value_with(self.falloff, dist)
    }

    /// [`PointLight::value_at`] of every distance of `dist`, into `out`. Each falloff has a
    /// loop of its own, with no branch inside, which the compiler turns into vector
    /// instructions (inlined, so that it takes the vector width of its caller: see
    /// [`crate::simd`]).
    #[inline(always)]
    pub fn values_at(&self, dist: &[f64], out: &mut [f64]) {
        // The falloff a constant in each loop, so the match inside `value_with` folds away.
        let fill = |out: &mut [f64], falloff: Falloff| {
            for (o, &d) in out.iter_mut().zip(dist) {
                *o = self.value_with(falloff, d);
            }
        };
        match self.falloff {
            Falloff::Linear => fill(out, Falloff::Linear),
            Falloff::Inverse => fill(out, Falloff::Inverse),
            Falloff::InverseSquare => fill(out, Falloff::InverseSquare),
            Falloff::Constant => fill(out, Falloff::Constant),
            Falloff::LocalMin => fill(out, Falloff::LocalMin),
            Falloff::InverseSquareSoft => fill(out, Falloff::InverseSquareSoft),
        }
    }

    /// [`PointLight::value_at`] as if the light's falloff were `falloff`.
    #[inline(always)]
    fn value_with(&self, falloff: Falloff, dist: f64) -> f64 {
        // Distances under one unit are clamped so 1/x stays finite.
        let scaled = (dist * self.atten).max(1.0);
        match falloff {
            Falloff::Linear => {
                if self.light >= 0.0 {
                    (self.light - scaled).max(0.0)
                } else {
                    (self.light + scaled).min(0.0)
                }
            }
            Falloff::Inverse => self.light * FALLOFF_SCALE / scaled,
            Falloff::InverseSquare => self.light * (FALLOFF_SCALE / scaled).powi(2),
            Falloff::Constant | Falloff::LocalMin => self.light,
            Falloff::InverseSquareSoft => {
                self.light * (FALLOFF_SCALE / (dist * self.atten + FALLOFF_SCALE)).powi(2)
            }
        }
    }

    /// Distance beyond which `|value_at|` stays below `gate` light units.
    pub fn range(&self, gate: f64) -> f64 {
        let l = self.light.abs();
        let gate = gate.max(1e-9);
        let r = match self.falloff {
            Falloff::Linear => l,
            Falloff::Inverse => l * FALLOFF_SCALE / gate,
            Falloff::InverseSquare => FALLOFF_SCALE * (l / gate).sqrt(),
            Falloff::InverseSquareSoft => FALLOFF_SCALE * ((l / gate).sqrt() - 1.0).max(0.0),
            Falloff::Constant | Falloff::LocalMin => return f64::INFINITY,
        };
        r / self.atten
    }

    /// The most light units, in any channel, this light adds at a point at least `dist`
    /// away, at any angle and inside any cone (every falloff dims with distance or not at
    /// all). `None` for lights whose light is not a sum (local minlight) or whose colour
    /// varies (a projected picture).
    pub fn brightest_beyond(&self, dist: f64) -> Option<f64> {
        if self.falloff == Falloff::LocalMin || self.projector.is_some() {
            return None;
        }
        // `angle_factor`'s largest value, at normal incidence or (for a negative scale) grazing.
        let angle = 1.0_f64.max(1.0 - self.anglescale);
        Some(self.value_at(dist).abs() * angle * self.color.abs().max_element())
    }

    /// Brightness this light adds at a point `dist` away in unit direction
    /// `to_point` (from the light), on a surface whose normal makes cosine
    /// `cos_incidence` with the direction back to the light.
    // Inlined into the per-sample loop of every face and light, which lives in another module.
    #[inline]
    pub fn contribution(&self, dist: f64, to_point: DVec3, cos_incidence: f64) -> f64 {
        self.contribution_of(self.value_at(dist), to_point, cos_incidence)
    }

    /// [`PointLight::contribution`] at a distance whose [`PointLight::value_at`] is `falloff`.
    #[inline]
    pub fn contribution_of(&self, falloff: f64, to_point: DVec3, cos_incidence: f64) -> f64 {
        let angle = if self.falloff == Falloff::LocalMin {
            f64::from(u8::from(cos_incidence > 0.0))
        } else {
            angle_factor(cos_incidence, self.anglescale)
        };
        let spot = self.spot.map_or(1.0, |s| s.factor(to_point));
        // No early way out for a zero factor: whether a sample faces the light changes from
        // sample to sample, and the product is zero anyway (of either sign, which light units
        // never tell apart: sums start at +0).
        falloff * angle * spot
    }
}

/// Spotlight cone (full angle, degrees) when `angle` is absent.
pub const DEFAULT_SPOT_ANGLE: f64 = 40.0;

/// `_deviance`: `light` as `count` lights spread through a ball of `radius`,
/// together as bright as the one light. Linear lights also divide their
/// fade rate, so each copy still reaches as far as the original; local
/// minlight raises to a level rather than adding, so its copies keep it.
pub fn split_light(light: &PointLight, radius: f64, count: usize) -> Vec<PointLight> {
    let n = count.max(1) as f64;
    ball_points(light.origin, radius, count.max(1))
        .into_iter()
        .map(|origin| {
            let mut copy = light.clone();
            copy.origin = origin;
            match light.falloff {
                Falloff::LocalMin => {}
                Falloff::Linear => {
                    copy.light /= n;
                    copy.atten /= n;
                }
                _ => copy.light /= n,
            }
            copy
        })
        .collect()
}

/// A white style-0 light at the origin for tests: `light` units with `falloff`, `wait` 1,
/// `_anglescale` 0.5, no cone, dirt or picture.
#[cfg(test)]
pub(crate) fn test_light(falloff: Falloff, light: f64) -> PointLight {
    PointLight {
        origin: DVec3::ZERO,
        light,
        atten: 1.0,
        falloff,
        color: DVec3::ONE,
        style: 0,
        spot: None,
        anglescale: 0.5,
        dirt: None,
        bounce: 1.0,
        light_channels: 1,
        shadow_channels: 1,
        entity: 0,
        projector: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(falloff: Falloff, value: f64, wait: f64) -> PointLight {
        PointLight {
            atten: wait,
            ..test_light(falloff, value)
        }
    }

    fn close(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9 * b.abs().max(1.0)
    }

    #[test]
    fn linear_falloff_reaches_zero_at_light_over_wait() {
        let l = light(Falloff::Linear, 300.0, 1.0);
        assert!(close(l.value_at(0.0), 299.0), "clamped to 1 unit");
        assert!(close(l.value_at(100.0), 200.0));
        assert_eq!(l.value_at(400.0), 0.0);
        assert!(close(l.range(0.001), 300.0));
        let l = light(Falloff::Linear, 300.0, 2.0);
        assert!(close(l.value_at(100.0), 100.0));
        assert!(close(l.range(0.001), 150.0));
        let neg = light(Falloff::Linear, -100.0, 1.0);
        assert!(close(neg.value_at(40.0), -60.0));
        assert_eq!(neg.value_at(500.0), 0.0);
    }

    #[test]
    fn inverse_falloffs_equal_light_at_128_units() {
        for f in [Falloff::Inverse, Falloff::InverseSquare] {
            let l = light(f, 200.0, 1.0);
            assert!(close(l.value_at(128.0), 200.0), "{f:?}");
            let at = l.range(0.5);
            assert!(close(l.value_at(at), 0.5), "{f:?} range");
        }
        let inv = light(Falloff::Inverse, 200.0, 1.0);
        assert!(close(inv.value_at(256.0), 100.0));
        let sq = light(Falloff::InverseSquare, 200.0, 1.0);
        assert!(close(sq.value_at(256.0), 50.0));
        assert!(close(sq.value_at(64.0), 800.0), "bright near the source");
        // Wait scales distance.
        let sq2 = light(Falloff::InverseSquare, 200.0, 2.0);
        assert!(close(sq2.value_at(64.0), 200.0));
    }

    #[test]
    fn soft_inverse_square_is_light_at_the_source() {
        let l = light(Falloff::InverseSquareSoft, 300.0, 1.0);
        assert!(close(l.value_at(0.0), 300.0));
        assert!(close(l.value_at(128.0), 75.0));
        assert!(close(l.value_at(l.range(0.25)), 0.25));
    }

    #[test]
    fn constant_and_local_min_ignore_distance() {
        for f in [Falloff::Constant, Falloff::LocalMin] {
            let l = light(f, 50.0, 1.0);
            assert_eq!(l.value_at(1.0e5), 50.0);
            assert_eq!(l.range(0.001), f64::INFINITY);
        }
        // Local minlight has no angle term: any surface facing it gets the full value.
        let l = light(Falloff::LocalMin, 50.0, 1.0);
        assert_eq!(l.contribution(10.0, DVec3::new(1.0, 0.0, 0.0), 0.01), 50.0);
        assert_eq!(l.contribution(10.0, DVec3::new(1.0, 0.0, 0.0), -0.5), 0.0);
    }

    proptest::proptest! {
        /// What light's per-sample cut relies on (`trace::points`): past its range, by the
        /// relative margin on the squared distance, a light adds less than the gate.
        #[test]
        fn past_its_range_a_light_adds_less_than_the_gate(
            falloff in proptest::sample::select(vec![
                Falloff::Linear,
                Falloff::Inverse,
                Falloff::InverseSquare,
                Falloff::InverseSquareSoft,
            ]),
            value in 1.0f64..5000.0,
            wait in 0.05f64..10.0,
            gate in 0.001f64..2.0,
            beyond in 0.0f64..3.0,
        ) {
            let l = light(falloff, value, wait);
            let range = l.range(gate);
            let dist = (range * range * (1.0 + 1e-9)).sqrt() * (1.0 + beyond);
            proptest::prop_assert!(l.value_at(dist).abs() < gate, "{} at {}", l.value_at(dist), dist);
        }
    }

    #[test]
    fn angle_factor_blends_cosine() {
        assert_eq!(angle_factor(1.0, 0.5), 1.0);
        assert!(close(angle_factor(0.0001, 0.5), 0.50005));
        assert_eq!(angle_factor(-0.1, 0.5), 0.0);
        assert_eq!(angle_factor(0.0, 0.5), 0.5, "grazing light counts");
        assert!(close(angle_factor(0.5, 1.0), 0.5));
        assert_eq!(angle_factor(0.3, 0.0), 1.0);
    }

    #[test]
    fn spotlight_cone_edges() {
        let down = DVec3::new(0.0, 0.0, -1.0);
        let at = |deg: f64| {
            let r = deg.to_radians();
            DVec3::new(r.sin(), 0.0, -r.cos())
        };
        // Default 40 degrees: 20 each side of the axis.
        let s = Spot::new(down, 0.0, 0.0);
        assert_eq!(s.factor(at(0.0)), 1.0);
        assert_eq!(s.factor(at(19.9)), 1.0);
        assert_eq!(s.factor(at(20.1)), 0.0);
        // 60 degree cone with a 20 degree soft inner cone.
        let s = Spot::new(down, 60.0, 20.0);
        assert_eq!(s.factor(at(9.9)), 1.0);
        assert_eq!(s.factor(at(30.1)), 0.0);
        let mid = s.factor(at(20.0));
        let want = (20f64.to_radians().cos() - 30f64.to_radians().cos())
            / (10f64.to_radians().cos() - 30f64.to_radians().cos());
        assert!(close(mid, want) && mid > 0.0 && mid < 1.0, "{mid}");
        // A soft angle wider than the cone is ignored.
        let s = Spot::new(down, 30.0, 50.0);
        assert_eq!(s.cos_inner, s.cos_outer);
    }

    #[test]
    fn deviance_copies_are_together_as_bright_and_as_far_reaching() {
        // Linear copies divide the fade rate too.
        let one = light(Falloff::Linear, 300.0, 1.0);
        let split = split_light(&one, 4.0, 3);
        let sum: f64 = split.iter().map(|l| l.value_at(100.0)).sum();
        assert!(close(sum, one.value_at(100.0)));
        assert!(close(split[0].range(0.001), one.range(0.001)));
    }
}
