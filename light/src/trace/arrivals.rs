//! Light that got through to a sample, on its way into the face's sums.
//!
//! Without dirt each arrival goes straight into the per-style sums. With dirt measured on the
//! face, arrivals wait until every shadow ray is traced, so occlusion is measured only where
//! some light that takes it arrived; they are then added in the order they came, so the sums
//! are the same as adding each as it was traced.

use super::sample_light::{SampleLight, StyleBuffers};
use crate::dirt::DirtFactors;
use crate::lights::{Falloff, PointLight, SunLight};

/// Where light arriving at a sample comes from.
#[derive(Debug, Clone, Copy)]
pub enum Source {
    /// A point light, and the style its light arrives in (its own, or the switchable shadow's
    /// that blocks it).
    Light {
        light: usize,
        style: u8,
    },
    Sun(usize),
}

/// Light that reached a sample (its shadow ray got through), before dirt.
#[derive(Debug, Clone, Copy)]
pub struct Arrival {
    source: Source,
    pub sample: u32,
    value: f64,
    /// The source takes dirt on this face.
    pub dirty: bool,
}

impl Arrival {
    pub fn new(source: Source, sample: usize, value: f64, dirty: bool) -> Arrival {
        Arrival {
            source,
            sample: sample as u32,
            value,
            dirty,
        }
    }
}

/// Where a face's arrivals go. With dirt measured they wait (dirt is measured
/// after the shadow rays, only where some light that takes it arrives); without,
/// they go straight into the sums, in the same order and so to the same sums
/// (an arrival is above the gate already: nothing darkens it).
#[derive(Debug, Default)]
pub struct Arrivals {
    pub waiting: Vec<Arrival>,
    wait: bool,
}

impl Arrivals {
    pub fn start_face(&mut self, wait: bool) {
        self.waiting.clear();
        self.wait = wait;
    }

    pub fn add(&mut self, a: Arrival, (lights, suns, points): Sources, out: &mut SampleLight) {
        if self.wait {
            self.waiting.push(a);
        } else {
            settle(&a, a.value, (lights, suns, points), out);
        }
    }

    /// [`Arrivals::add`] for light `li` arriving in `style` at each `(sample, value)` of
    /// `arrived` (samples at `points`), in one go when nothing waits.
    pub fn add_light(
        &mut self,
        (li, light, style): (usize, &PointLight, u8),
        arrived: impl Iterator<Item = (usize, f64)> + Clone,
        dirty: bool,
        points: &[[f32; 3]],
        out: &mut SampleLight,
    ) {
        if self.wait {
            let source = Source::Light { light: li, style };
            self.waiting
                .extend(arrived.map(|(i, v)| Arrival::new(source, i, v, dirty)));
        } else {
            deposit(light, style, arrived, points, out);
        }
    }

    /// Adds the arrivals that waited for dirt, each darkened by its source's response
    /// (`dirt`), in the order they were found, so sums come out the same as adding each light
    /// as it is traced; those that dirt takes below `gate` are dropped.
    pub fn settle_waiting(
        &self,
        (lights, suns, points): Sources,
        dirt: &mut DirtFactors,
        gate: f64,
        out: &mut SampleLight,
    ) {
        for a in &self.waiting {
            let i = a.sample as usize;
            let response = match a.source {
                Source::Light { light, .. } => lights[light].dirt,
                Source::Sun(si) => suns[si].dirt,
            };
            let v = a.value * dirt.get(response).map_or(1.0, |d| f64::from(d[i]));
            // Dirt may take it below the gate: then it is dropped.
            if v.abs() < gate {
                continue;
            }
            settle(a, v, (lights, suns, points), out);
        }
    }
}

/// Where arrivals come from, and the face's sample points they arrive at.
pub type Sources<'a> = (&'a [PointLight], &'a [SunLight], &'a [[f32; 3]]);

/// Adds arrival `a` to `out` at `value` (its value after dirt).
fn settle(a: &Arrival, value: f64, (lights, suns, points): Sources, out: &mut SampleLight) {
    let i = a.sample as usize;
    match a.source {
        Source::Light { light, style } => {
            deposit(
                &lights[light],
                style,
                std::iter::once((i, value)),
                points,
                out,
            );
        }
        Source::Sun(si) => {
            let sun = &suns[si];
            let slot = &mut out.sums.get(sun.style)[i];
            for (o, c) in slot.iter_mut().zip(sun.color.to_array()) {
                *o += (value * c) as f32;
            }
            if let Some(d) = &mut out.directions {
                d.add_from_sun(sun.style, i, sun.to_sun, value * brightness(sun.color));
            }
        }
    }
}

/// Adds `value` of `light` (its colour at the sample's point) in `style` to sample `i` for each
/// `(i, value)` of `arrived`, or for a local minlight raises the sample's floor to it.
/// The part of a light's light that does not bounce (all of a `_bounce 0` light's, the rest of
/// its `_bouncescale`) is also kept in `no_bounce`, so it can be taken out of what reflects (a
/// scale above 1 keeps a negative part, which adds).
fn deposit(
    light: &PointLight,
    style: u8,
    arrived: impl Iterator<Item = (usize, f64)> + Clone,
    points: &[[f32; 3]],
    out: &mut SampleLight,
) {
    let local_min = light.falloff == Falloff::LocalMin;
    // Without a projector every sample takes the light's one colour.
    let fixed = light.projector.is_none().then_some(light.color);
    let color =
        |i: usize| fixed.unwrap_or_else(|| light.color_at(glam::Vec3::from(points[i]).as_dvec3()));
    // A local minlight raises the floor to its light; any other light adds to the sum.
    if local_min {
        let floors = out.floors.get(style);
        combine_into(floors, arrived.clone(), color, |o, v| *o = o.max(v));
    } else {
        let sums = out.sums.get(style);
        combine_into(sums, arrived.clone(), color, |o, v| *o += v);
    }
    if let Some(d) = out.directions.as_mut().filter(|_| !local_min) {
        for (i, value) in arrived.clone() {
            d.add_from_point(style, i, light.origin, value * brightness(color(i)));
        }
    }
    let kept_share = 1.0 - f64::from(light.bounce);
    if !local_min && kept_share != 0.0 {
        let len = out.sums.len;
        let kept = out.no_bounce.get_or_insert_with(|| StyleBuffers::new(len));
        let buffer = kept.get(style);
        for (i, value) in arrived {
            for (o, c) in buffer[i].iter_mut().zip(color(i).to_array()) {
                *o += (value * c * kept_share) as f32;
            }
        }
    }
}

/// Each `(i, value)` of `arrived` (the light's colour at sample `i` times `value`) combined
/// channel by channel into sample `i` of `buffer`.
fn combine_into(
    buffer: &mut [[f32; 3]],
    arrived: impl Iterator<Item = (usize, f64)>,
    color: impl Fn(usize) -> glam::DVec3,
    combine: impl Fn(&mut f32, f32),
) {
    for (i, value) in arrived {
        for (o, c) in buffer[i].iter_mut().zip(color(i).to_array()) {
            combine(o, (value * c) as f32);
        }
    }
}

/// How bright a colour is, for weighing directions: the mean of its channels.
fn brightness(color: glam::DVec3) -> f64 {
    color.element_sum() / 3.0
}
