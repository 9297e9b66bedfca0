//! Direct light of one face: what every light, sun and minlight gives each of its samples.
//!
//! [`trace_face`] works through a face in four steps, each in a module of its own:
//!
//! 1. Point lights ([`points`]): the lights whose reach may touch the face's box
//!    ([`LightReaches`]) are culled by the face's plane, their range and the PVS; each
//!    remaining light's unshadowed value is worked out per sample, and the samples it reaches
//!    are found with shadow rays, 16 neighbouring samples to a packet (coherent rays;
//!    [`shadows`]). Each sample takes the light at its point, however close the light is
//!    (as ericw-tools takes it).
//! 2. Suns and sky domes ([`suns`]): a face that sees no sky in the PVS skips them, and a
//!    direction that meets none of the sky boxes it sees is skipped; a sun ray counts only
//!    when the first thing it meets is sky.
//! 3. Dirt: light that takes dirt waits ([`arrivals`]) until the shadow rays are done, so
//!    occlusion ([`crate::dirt`]) is measured only at samples it reaches; then it is added,
//!    darkened, in the order it arrived.
//! 4. Minlight: a floor under style 0 (or, with `--addmin`, added to it).
//!
//! The result ([`SampleLight`], per sample and style) waits for bounced light before
//! [`SampleLight::finish`] applies the floors and averages samples to luxels.

mod arrivals;
mod hulls;
mod points;
mod sample_light;
mod shadows;
pub(crate) mod suns;

use glam::Vec3;
use quake_formats::geom::Bounds;

use crate::dirt::{DirtFactors, DirtNeed, DirtResponse, DirtSampling, FaceDirt, face_occlusion};
use crate::embree::RayPacket16;
use crate::faces::FaceGeom;
use crate::lights::mottle::mottle;
use crate::lights::{Minlight, PointLight, SunLight};
use crate::reach::LightReaches;
use crate::samples::FaceSamples;
use crate::scene::TraceScene;
use crate::visibility::Visibility;
use arrivals::Arrivals;
use sample_light::Directions;
use sample_light::StyleBuffers;
pub use sample_light::{HiddenLuxels, SampleLight};
use shadows::VisibilityScratch;

/// Shadow rays stop this far short of the light, so a light sitting right
/// on a surface is not blocked by it.
pub(crate) const LIGHT_CLEARANCE: f32 = 0.1;

/// Rays from a sample point start this far along (units): Embree's robust scenes count a hit
/// at the very origin, and a sample on the edge of its face can lie exactly in the plane of a
/// face beside it that does not hold it, which would then block every ray it casts.
pub(crate) const RAY_START: f32 = 0.01;

/// Everything shared by all faces while tracing.
pub struct TraceSetup<'a> {
    pub faces: &'a [FaceGeom],
    pub scene: &'a TraceScene,
    pub vis: &'a Visibility,
    /// Entity lights and surface-light copies.
    pub lights: &'a [PointLight],
    /// World leaf of each light (None: in solid or outside; no PVS culling).
    pub light_leafs: &'a [Option<u32>],
    /// Each light's cut-off, from [`crate::reach::light_reaches`] with `gate`.
    pub light_reaches: &'a LightReaches,
    pub suns: &'a [SunLight],
    /// Skip lights that cannot reach a face (range, plane side, PVS, sky PVS).
    pub cull: bool,
    /// Contributions below this many light units count as zero.
    pub gate: f64,
    /// Length of sun rays (longer than the map's diagonal).
    pub sun_distance: f32,
    /// How to measure dirt; `None` when no light, sun or minlight takes dirt.
    pub dirt: Option<DirtSampling>,
    /// Supersampled faces trace sub-samples only where luxels disagree
    /// (see `VisibilityScratch::trace`); off for the reference.
    pub adaptive: bool,
    /// Keep the directions light arrives from (for deluxemaps).
    pub directions: bool,
    /// Each sample's light as traced, before the fill of samples in solid and the minlight
    /// floor, is read (bounce reflects it, deluxemaps keep its directions): then samples in
    /// solid need their rays, and light under the floor still counts.
    pub raw_light_read: bool,
    /// Light units by which the shadows of a face's faintest lights may be misjudged,
    /// together, at any sample: those lights are traced with a few probes
    /// (`VisibilityScratch::trace_faint`). Zero: every light is traced in full.
    pub faint_budget: f64,
}

/// What one face takes from the lights (set per brush model).
#[derive(Debug, Clone, Copy)]
pub struct FaceRules<'a> {
    /// The floor for style 0 (none for a face its model's `_minlight_exclude` names).
    pub minlight: Option<&'a Minlight>,
    /// `_minlight_mottle`: [`crate::lights::mottle::mottle`] is added to the floor.
    pub minlight_mottle: bool,
    /// Dirt may darken this face (false for models with `_dirt -1`).
    pub dirt: bool,
    /// `_lightignore`: minlight only, no lights or suns.
    pub minlight_only: bool,
    /// The light channels the face's model receives light on (`_object_channel_mask`; suns,
    /// surface lights and bounced light are on channel 1).
    pub channels: u32,
    /// `_maxlight`: the most light a sample takes, in levels (`None`: no cap).
    pub maxlight: Option<f64>,
    /// `_lightcolorscale`: how much colour the light keeps (`None`: all of it).
    pub color_scale: Option<f32>,
    /// Bounced light will be added and darkened by dirt this way: dirt is
    /// then measured at every sample (bounce reaches where lights do not).
    pub bounce_dirt: Option<DirtResponse>,
}

impl Default for FaceRules<'_> {
    /// Every light and sun, on channel 1; no minlight, dirt, cap or bounce dirt.
    fn default() -> Self {
        FaceRules {
            minlight: None,
            minlight_mottle: false,
            dirt: false,
            minlight_only: false,
            channels: 1,
            maxlight: None,
            color_scale: None,
            bounce_dirt: None,
        }
    }
}

/// Per-luxel colour of each style a face receives, in light units.
#[derive(Debug, Clone, PartialEq)]
pub struct FaceLight {
    /// The face's index.
    pub face: usize,
    /// Luxels across (s).
    pub width: usize,
    /// Luxels down (t).
    pub height: usize,
    /// Style and its luxels (row-major), style 0 first.
    pub styles: Vec<(u8, Vec<[f32; 3]>)>,
    /// When deluxemaps are wanted: per style, each luxel's mean direction of arriving light in
    /// the face's tangent space (unit; zero where none arrived). Styles not listed have none.
    pub directions: Vec<(u8, Vec<[f32; 3]>)>,
}

/// Work done lighting one face.
#[derive(Debug, Clone, Copy, Default)]
pub struct TraceCounts {
    pub shadow_rays: u64,
    pub sun_rays: u64,
    pub dirt_rays: u64,
    /// Face/light pairs looked at, and how many of them culling skipped.
    pub pairs: u64,
    pub pairs_culled: u64,
}

impl TraceCounts {
    pub fn add(&mut self, o: &TraceCounts) {
        self.shadow_rays += o.shadow_rays;
        self.sun_rays += o.sun_rays;
        self.dirt_rays += o.dirt_rays;
        self.pairs += o.pairs;
        self.pairs_culled += o.pairs_culled;
    }
}

/// Working buffers of [`trace_face`] that one thread keeps from face to face, so no face
/// allocates them or grows them anew.
#[derive(Debug, Default)]
pub struct TraceScratch {
    arrivals: Arrivals,
    value: Vec<f64>,
    /// The face's sample points, for measuring their distances to lights.
    points: points::SamplePoints,
    /// How the current light lies from each sample.
    toward: points::Toward,
    /// The lights that may reach the face ([`LightReaches::near`]), and its scratch.
    near_lights: Vec<u32>,
    near_seen: Vec<u64>,
    /// Those of them that are not culled, in the same order.
    kept_lights: Vec<KeptLight>,
    /// Indices into `kept_lights`, faintest first.
    faintest_first: Vec<u32>,
    visibility: VisibilityScratch,
}

/// A light that may light a face, and how brightly at most.
#[derive(Debug, Clone, Copy)]
struct KeptLight {
    light: u32,
    /// The most light units it adds to any sample of the face.
    brightest: f64,
    /// Traced with a few probes (`VisibilityScratch::trace_faint`).
    faint: bool,
}

/// Lights one face's samples: the light per sample, before floors.
pub fn trace_face(
    setup: &TraceSetup,
    samples: &FaceSamples,
    rules: &FaceRules,
    reuse: &mut TraceScratch,
) -> (SampleLight, TraceCounts) {
    let mut face = FaceTrace::new(setup, samples, rules, reuse);
    face.point_lights();
    face.suns();
    let occlusion = face.occlusion();
    let mut dirt = DirtFactors::new(&occlusion, samples.points.len());
    face.scratch.arrivals.settle_waiting(
        (face.lights, face.suns, &samples.points),
        &mut dirt,
        setup.gate,
        &mut face.out,
    );
    face.minlight(&mut dirt);
    if let Some(d) = dirt.get(rules.bounce_dirt) {
        face.out.bounce_dirt = d.to_vec();
    }
    (face.out, face.counts)
}

/// One face being traced: what it reads, the buffers it works in and what it has found.
struct FaceTrace<'a> {
    setup: &'a TraceSetup<'a>,
    samples: &'a FaceSamples,
    rules: &'a FaceRules<'a>,
    face: &'a FaceGeom,
    /// The box around the samples.
    bounds: Bounds,
    /// How dirt is measured on this face (`None`: nothing on it takes dirt).
    dirt: Option<DirtSampling>,
    /// The lights and suns the face takes (none for `_lightignore`).
    lights: &'a [PointLight],
    suns: &'a [SunLight],
    packet: RayPacket16,
    scratch: &'a mut TraceScratch,
    out: SampleLight,
    counts: TraceCounts,
}

impl<'a> FaceTrace<'a> {
    fn new(
        setup: &'a TraceSetup<'a>,
        samples: &'a FaceSamples,
        rules: &'a FaceRules<'a>,
        scratch: &'a mut TraceScratch,
    ) -> FaceTrace<'a> {
        let n = samples.points.len();
        let out = SampleLight {
            face: samples.face,
            width: samples.width,
            height: samples.height,
            per_luxel: samples.per_luxel(),
            sums: StyleBuffers::new(n),
            // Local-minlight (delay 4) lights raise luxels to a floor instead of adding.
            floors: StyleBuffers::none_yet(n),
            added_minlight: None,
            no_bounce: None,
            bounce_dirt: Vec::new(),
            directions: setup.directions.then(|| {
                let face = &setup.faces[samples.face];
                Directions::new(&samples.points, &face.vecs, face.plane.normal)
            }),
            occluded: samples.occluded.clone(),
            // ericw-tools caps its samples at twice the level, before the range scale.
            max_sample: rules.maxlight.map(|level| (2.0 * level) as f32),
            color_scale: rules.color_scale,
        };
        let mut bounds = Bounds::EMPTY;
        for &p in &samples.points {
            bounds.add_point(Vec3::from(p).as_dvec3());
        }
        // Dirt is measured after the shadow rays, only where some light that
        // takes it arrives (many samples are dark).
        let dirt = setup.dirt.filter(|_| rules.dirt);
        // A world face with every sample inside solid (buried in a wall, never drawn) takes
        // no light but minlight, as ericw-tools' samples in solid take none.
        let buried = setup.faces[samples.face].model == 0
            && !samples.occluded.is_empty()
            && !samples.occluded.contains(&false);
        let (lights, suns) = if rules.minlight_only || buried {
            (&[][..], &[][..])
        } else if rules.channels & 1 == 0 {
            // Suns are on channel 1.
            (setup.lights, &[][..])
        } else {
            (setup.lights, setup.suns)
        };
        scratch.visibility.start_face(samples, setup.raw_light_read);
        scratch.arrivals.start_face(dirt.is_some());
        scratch.value.clear();
        scratch.value.resize(n, 0.0);
        scratch.points.set(&samples.points);
        FaceTrace {
            setup,
            samples,
            rules,
            face: &setup.faces[samples.face],
            bounds,
            dirt,
            lights,
            suns,
            packet: RayPacket16::new(),
            scratch,
            out,
            counts: TraceCounts::default(),
        }
    }

    /// Whether light with this dirt response is darkened by dirt on this face.
    fn takes_dirt(&self, response: Option<DirtResponse>) -> bool {
        response.is_some() && self.dirt.is_some()
    }

    /// Dirt occlusion per sample where something that takes dirt arrived (or, when bounced
    /// light or minlight takes it, everywhere); empty when nothing on the face takes dirt.
    fn occlusion(&mut self) -> Vec<f32> {
        let Some(sampling) = self.dirt else {
            return Vec::new();
        };
        let everywhere = if self.rules.minlight.is_some_and(|m| m.dirt.is_some()) {
            DirtNeed::Light
        } else if self.rules.bounce_dirt.is_some() {
            DirtNeed::Bounce
        } else {
            DirtNeed::No
        };
        let mut needed = vec![everywhere; self.samples.points.len()];
        for a in self.scratch.arrivals.waiting.iter().filter(|a| a.dirty) {
            needed[a.sample as usize] = DirtNeed::Light;
        }
        // An occluded sample's light does not count (unless every sample of the face is
        // occluded); its dirt, measured from inside solid, would spoil its neighbours'.
        let occluded = &self.samples.occluded;
        if occluded.contains(&false) {
            for (n, _) in needed.iter_mut().zip(occluded).filter(|(_, o)| **o) {
                *n = DirtNeed::No;
            }
        }
        let (values, rays) = face_occlusion(
            FaceDirt {
                scene: self.setup.scene,
                samples: self.samples,
                model: self.face.model,
                channels: self.rules.channels,
                sampling: &sampling,
                first_at: &self.scratch.visibility.first_at,
                needed: &needed,
            },
            self.setup.adaptive,
        );
        self.counts.dirt_rays += rays;
        values
    }

    /// The face's minlight (times its dirt factor when minlight takes dirt): a floor under
    /// style 0, or added to it with `--addmin`.
    fn minlight(&mut self, dirt: &mut DirtFactors) {
        let Some(m) = self.rules.minlight else {
            return;
        };
        let n = self.samples.points.len();
        let dirt = dirt.get(m.dirt);
        let points = &self.samples.points;
        // The mottle raises the floor, as in ericw-tools; minlight that adds is never mottled.
        let mottled = self.rules.minlight_mottle && !m.add;
        let values = (0..n).map(|i| {
            let mut level = m.level * dirt.map_or(1.0, |d| f64::from(d[i]));
            if mottled {
                level += mottle(Vec3::from(points[i]).as_dvec3());
            }
            m.color.to_array().map(|c| (level * c) as f32)
        });
        if m.add {
            self.out.added_minlight = Some(values.collect());
        } else {
            for (f, v) in self.out.floors.get(0).iter_mut().zip(values) {
                for k in 0..3 {
                    f[k] = f[k].max(v[k]);
                }
            }
        }
    }
}
