//! The render settings a page sends, as JSON: every field optional (what is left out keeps the
//! value `raywave view` was started with), unknown fields refused, every number range-checked
//! before any work starts, so a bad request is a 400 with a message, never a panic or a
//! render that cannot finish.

use super::http::ApiError;
use crate::output::cost_map::{CostKind, Count};
use crate::render::engine::Engine;
use crate::render::quote::quote;
use crate::render::sampling::LightSampler;
use crate::render::scene::Camera;
use crate::render::settings::{LightModel, RenderSettings, ShadowMode};
use glam::Vec3;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};

/// The largest image side the viewer renders (the command line allows more; a browser tab does
/// not need it, and a render must stay interactive).
pub const MAX_SIDE: u32 = 2048;
/// The most camera samples (pixels × aa) one render may take.
pub const MAX_CAMERA_SAMPLES: u64 = 4 << 20;
/// The most shadow points per light.
const MAX_SHADOW_SAMPLES: u32 = 4096;
/// The most mirror bounces (the command line's bound).
const MAX_BOUNCES: u32 = 64;

/// A pinhole camera as the page sends it (degrees, not radians).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CameraJson {
    /// Eye position.
    pub position: [f32; 3],
    /// The point looked at.
    pub look_at: [f32; 3],
    /// Up hint.
    pub up: [f32; 3],
    /// Full field of view in degrees, in (0, 180).
    pub fov_degrees: f32,
}

impl CameraJson {
    /// The scene camera as JSON.
    fn from_camera(c: &Camera) -> Self {
        CameraJson {
            position: c.position.to_array(),
            look_at: c.point_of_interest.to_array(),
            up: c.up.to_array(),
            fov_degrees: c.fov.to_degrees(),
        }
    }

    /// The camera, or a 400 naming what is wrong with it.
    fn to_camera(self) -> Result<Camera, ApiError> {
        let all = [self.position, self.look_at, self.up];
        if all
            .iter()
            .flatten()
            .any(|v| !v.is_finite() || v.abs() > 1e6)
        {
            return Err(ApiError::bad(
                "camera: expected finite coordinates of magnitude at most 1e6",
            ));
        }
        let [p, l, u] = all.map(Vec3::from_array);
        let forward = l - p;
        if forward.length() < 1e-6 {
            return Err(ApiError::bad(
                "camera: position and look_at are the same point: expected a direction to look in",
            ));
        }
        if forward.normalize().cross(u).length() < 1e-6 {
            return Err(ApiError::bad(
                "camera: up is zero or parallel to the view direction",
            ));
        }
        if !(self.fov_degrees > 0.0 && self.fov_degrees < 180.0) {
            return Err(ApiError::bad(format!(
                "camera: fov_degrees must be in (0, 180), found {}",
                self.fov_degrees
            )));
        }
        Ok(Camera {
            position: p,
            point_of_interest: l,
            up: u,
            fov: self.fov_degrees.to_radians(),
        })
    }
}

/// Which rays the render's cost-map overlay counts (`render --cost-kind`), or none.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum CostOverlay {
    /// No overlay: the render is not counted.
    #[default]
    Off,
    /// Camera rays' closest hits.
    Camera,
    /// Shadow rays' occlusion tests.
    Shadow,
    /// Mirror rays' closest hits.
    Reflection,
    /// Every ray.
    All,
}

impl CostOverlay {
    /// The cost map's kind, or `None` for no overlay.
    pub(crate) fn kind(self) -> Option<CostKind> {
        match self {
            CostOverlay::Off => None,
            CostOverlay::Camera => Some(CostKind::Camera),
            CostOverlay::Shadow => Some(CostKind::Shadow),
            CostOverlay::Reflection => Some(CostKind::Reflection),
            CostOverlay::All => Some(CostKind::All),
        }
    }
}

/// The settings a page sends: every field optional.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ViewSettings {
    /// Image width.
    pub width: Option<u32>,
    /// Image height.
    pub height: Option<u32>,
    /// Mirror bounces.
    pub bounces: Option<u32>,
    /// off, hard or soft.
    pub shadows: Option<ShadowMode>,
    /// Points per light with soft shadows.
    pub shadow_samples: Option<u32>,
    /// random, stratified, sobol or lab.
    pub sampler: Option<LightSampler>,
    /// lab or rpi.
    pub light_model: Option<LightModel>,
    /// wavefront or reference.
    pub engine: Option<Engine>,
    /// Camera rays per pixel.
    pub aa: Option<u32>,
    /// The seed of every random number.
    pub seed: Option<u32>,
    /// The render's camera (the scene's when left out).
    pub camera: Option<CameraJson>,
    /// The cost-map overlay: off, camera, shadow, reflection or all (wavefront engine only).
    pub cost_map: Option<CostOverlay>,
    /// What the overlay shows: nodes or tests.
    pub cost_measure: Option<Count>,
}

/// Settings checked and filled in: what a render job or a ray tree is computed with.
#[derive(Clone, Debug, PartialEq)]
pub struct Resolved {
    /// The render settings.
    pub settings: RenderSettings,
    /// The engine.
    pub engine: Engine,
    /// The camera (the scene's, or the page's).
    pub camera: Camera,
    /// The cost-map overlay (off: the render is not counted).
    pub cost_map: CostOverlay,
    /// What the overlay shows.
    pub cost_measure: Count,
}

/// `v`, or a 400 saying `name` must be in `lo..=hi`.
pub(crate) fn in_range(name: &str, v: u32, lo: u32, hi: u32) -> Result<u32, ApiError> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(ApiError::bad(format!(
            "{name} must be in {lo}..={hi}, found {v}"
        )))
    }
}

/// Parses a request body (blank: every default): malformed JSON, unknown fields and wrong
/// types are a 400 naming `what` and the place (serde's line and column).
pub(crate) fn parse_json<T: Default + DeserializeOwned>(
    body: &[u8],
    what: &str,
) -> Result<T, ApiError> {
    if body.iter().all(u8::is_ascii_whitespace) {
        return Ok(T::default());
    }
    serde_json::from_slice(body)
        .map_err(|e| ApiError::bad(format!("{what}: {}", quote(&e.to_string()))))
}

impl ViewSettings {
    /// These settings over `base`, checked.
    pub fn resolve(&self, base: &Resolved) -> Result<Resolved, ApiError> {
        let mut s = base.settings.clone();
        let ranged = [
            ("width", self.width, &mut s.width, 1, MAX_SIDE),
            ("height", self.height, &mut s.height, 1, MAX_SIDE),
            ("bounces", self.bounces, &mut s.bounces, 0, MAX_BOUNCES),
            (
                "shadow_samples",
                self.shadow_samples,
                &mut s.shadow_samples,
                1,
                MAX_SHADOW_SAMPLES,
            ),
            ("aa", self.aa, &mut s.aa_samples, 1, 64),
        ];
        for (name, given, field, lo, hi) in ranged {
            if let Some(v) = given {
                *field = in_range(name, v, lo, hi)?;
            }
        }
        s.shadows = self.shadows.unwrap_or(s.shadows);
        s.sampler = self.sampler.unwrap_or(s.sampler);
        s.light_model = self.light_model.unwrap_or(s.light_model);
        s.seed = self.seed.unwrap_or(s.seed);
        let samples = s.width as u64 * s.height as u64 * s.aa_samples as u64;
        if samples > MAX_CAMERA_SAMPLES {
            return Err(ApiError::bad(format!(
                "width × height × aa = {samples} camera samples: the viewer renders at most {MAX_CAMERA_SAMPLES}"
            )));
        }
        s.check_sampler()
            .map_err(|e| ApiError::bad(e.to_string()))?;
        let camera = match &self.camera {
            Some(c) => c.to_camera()?,
            None => base.camera,
        };
        let engine = self.engine.unwrap_or(base.engine);
        let cost_map = self.cost_map.unwrap_or(base.cost_map);
        if cost_map != CostOverlay::Off && engine != Engine::Wavefront {
            return Err(ApiError::bad(
                "cost_map counts the wavefront engine's traversal: expected engine wavefront, or cost_map off",
            ));
        }
        Ok(Resolved {
            settings: s,
            engine,
            camera,
            cost_map,
            cost_measure: self.cost_measure.unwrap_or(base.cost_measure),
        })
    }
}

impl Resolved {
    /// The settings as the page reads them back (all fields set).
    pub fn to_json(&self) -> ViewSettings {
        let s = &self.settings;
        ViewSettings {
            width: Some(s.width),
            height: Some(s.height),
            bounces: Some(s.bounces),
            shadows: Some(s.shadows),
            shadow_samples: Some(s.shadow_samples),
            sampler: Some(s.sampler),
            light_model: Some(s.light_model),
            engine: Some(self.engine),
            aa: Some(s.aa_samples),
            seed: Some(s.seed),
            camera: Some(CameraJson::from_camera(&self.camera)),
            cost_map: Some(self.cost_map),
            cost_measure: Some(self.cost_measure),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(body: &[u8]) -> Result<ViewSettings, ApiError> {
        parse_json(body, "settings")
    }

    fn base() -> Resolved {
        Resolved {
            settings: RenderSettings::preview(),
            engine: Engine::Wavefront,
            camera: Camera::default(),
            cost_map: CostOverlay::Off,
            cost_measure: Count::Nodes,
        }
    }

    #[test]
    fn empty_body_keeps_the_base() {
        let r = parse(b" \n").unwrap().resolve(&base()).unwrap();
        assert_eq!(r, base());
    }

    #[test]
    fn fields_override_and_round_trip() {
        let body = br#"{"width": 40, "shadows": "soft", "shadow_samples": 9, "sampler": "sobol",
                        "engine": "reference", "light_model": "rpi"}"#;
        let r = parse(body).unwrap().resolve(&base()).unwrap();
        assert_eq!(r.settings.width, 40);
        assert_eq!(r.settings.height, 64);
        assert_eq!(r.settings.shadows, ShadowMode::Soft);
        assert_eq!(r.settings.sampler, LightSampler::Sobol);
        assert_eq!(r.settings.light_model, LightModel::Rpi);
        assert_eq!(r.engine, Engine::Reference);
        let again = r.to_json().resolve(&base()).unwrap();
        assert_eq!(again.settings, r.settings);
        let body = br#"{"cost_map": "shadow", "cost_measure": "tests"}"#;
        let r = parse(body).unwrap().resolve(&base()).unwrap();
        assert_eq!(
            (r.cost_map, r.cost_measure),
            (CostOverlay::Shadow, Count::Tests)
        );
        assert_eq!(r.to_json().resolve(&base()).unwrap(), r);
    }

    #[test]
    fn bad_settings_are_refused_with_the_reason() {
        let cases: [(&[u8], &str); 10] = [
            (b"{", "EOF"),
            (br#"{"widht": 3}"#, "unknown field"),
            (br#"{"width": "x"}"#, "invalid type"),
            (br#"{"width": 0}"#, "width must be in 1..=2048"),
            (br#"{"sampler": "best"}"#, "unknown variant"),
            (
                br#"{"shadows": "soft", "sampler": "bluenoise", "shadow_samples": 300}"#,
                "--sampler bluenoise with 300 points per light",
            ),
            (br#"{"width": 2048, "height": 2048, "aa": 4}"#, "camera samples"),
            (
                br#"{"cost_map": "shadow", "engine": "reference"}"#,
                "cost_map counts the wavefront engine's traversal",
            ),
            (br#"{"cost_map": "sideways"}"#, "unknown variant"),
            (
                br#"{"camera": {"position": [0,0,1], "look_at": [0,0,1], "up": [0,1,0], "fov_degrees": 30}}"#,
                "same point",
            ),
        ];
        for (body, expected) in cases {
            let err = parse(body).and_then(|v| v.resolve(&base())).unwrap_err();
            assert_eq!(err.status, 400);
            assert!(
                err.message.contains(expected),
                "{:?}: {}",
                String::from_utf8_lossy(body),
                err.message
            );
        }
    }
}
