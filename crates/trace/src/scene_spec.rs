//! The picture scene of `brtf render image`, as plain numbers.
//!
//! A [`SceneSpec`] says what to show (a unit sphere standing on a disk,
//! the disk or the sphere alone, all made of the sample material), the
//! light (a distant source or a spherical lamp, giving a chosen
//! irradiance at the origin, plus a constant background), the camera
//! (aimed at the sphere from a polar angle, azimuth and distance) and the
//! integrator settings. It validates its numbers ([`SceneSpec::validate`]),
//! builds the brtf-trace [`Scene`] and [`Camera`] for a [`Shader`]
//! ([`SceneSpec::build`]) and writes the same scene as Radiance text for
//! `rpict` ([`SceneSpec::radiance_text`]).
//!
//! The error messages name the `brtf render image` options the fields
//! come from (`--irradiance`, `--light-apex`, …).

use brtf_model::Rgb;
use glam::DVec3;
use std::f64::consts::PI;

use crate::camera::Camera;
use crate::integrator::ImageOptions;
use crate::integrator::Settings;
use crate::scene::{Scene, Shape, Source};
use crate::shader::Shader;

/// Radius of the floor disk.
pub const FLOOR_RADIUS: f64 = 6.0;
/// Centre of the sphere.
pub const BALL_CENTER: DVec3 = DVec3::new(0.0, 0.0, 1.0);
/// Radius of the sphere.
pub(crate) const BALL_RADIUS: f64 = 1.0;
/// The name the Radiance text's floor and sphere use as their modifier:
/// the material primitive given to [`SceneSpec::radiance_text`] must
/// carry it.
pub const MATERIAL_NAME: &str = "sample";
/// The largest picture, in pixels.
pub(crate) const MAX_PIXELS: usize = 64_000_000;

/// What the picture shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SceneKind {
    /// A unit sphere standing on a disk of radius 6.
    SpherePlane,
    /// The disk only.
    Plane,
    /// The sphere only.
    Sphere,
}

brtf_model::option_words!(SceneKind {
    SpherePlane => "sphere-plane",
    Plane => "plane",
    Sphere => "sphere",
});

impl SceneKind {
    /// True when the floor disk is in the scene.
    pub fn has_floor(self) -> bool {
        self != SceneKind::Sphere
    }

    /// True when the sphere is in the scene.
    pub fn has_ball(self) -> bool {
        self != SceneKind::Plane
    }
}

/// The kind of light source.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum LightKind {
    /// A distant source (Radiance `source`).
    Distant,
    /// A spherical light (a `sphere` with a `light` material).
    Sphere,
}

brtf_model::option_words!(LightKind { Distant => "distant", Sphere => "sphere" });

/// The light: its kind, where it is and how bright.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LightSpec {
    /// Distant source or spherical lamp.
    pub kind: LightKind,
    /// Polar angle of the light from the zenith, degrees.
    pub theta: f64,
    /// Azimuth of the light, degrees.
    pub phi: f64,
    /// Distant source: full apex angle, degrees (the sun: 0.53).
    pub apex: f64,
    /// Sphere light: distance of its centre from the origin.
    pub lamp_distance: f64,
    /// Sphere light: radius.
    pub lamp_radius: f64,
    /// Irradiance the source gives at the origin, normal to it (W/m²).
    pub irradiance: f64,
    /// Radiance of the constant background, as a fraction of irradiance/π.
    pub background: f64,
}

/// The camera and the picture size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViewSpec {
    /// Camera polar angle from the zenith, degrees.
    pub theta: f64,
    /// Camera azimuth, degrees.
    pub phi: f64,
    /// Camera distance from its target (the sphere, or the origin for the plane).
    pub distance: f64,
    /// Horizontal field of view, degrees.
    pub fov: f64,
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
}

/// The whole picture scene. [`SceneSpec::DEFAULT`] holds the defaults of
/// `brtf render image`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SceneSpec {
    /// What to show.
    pub scene: SceneKind,
    /// The light source and background.
    pub light: LightSpec,
    /// The camera.
    pub view: ViewSpec,
    /// Integrator settings (ignored with `direct_only`).
    pub settings: Settings,
    /// Direct light only: no specular or diffuse rays, no background (as
    /// `rpict -ab 0 -av 0 0 0 -st 1`).
    pub direct_only: bool,
}

/// A number of a [`SceneSpec`] that cannot make a picture.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SceneSpecError {
    #[error("image size must be between 1×1 and 64 Mpixel")]
    ImageSize { width: usize, height: usize },
    #[error("--irradiance must be positive")]
    Irradiance(f64),
    #[error("--light-apex must be in (0, 170) degrees")]
    LightApex(f64),
    #[error("the lamp must clear the sphere")]
    Lamp { distance: f64, radius: f64 },
    #[error("--background must be a finite number ≥ 0")]
    Background(f64),
    #[error("--{0} must be a finite number")]
    NotFinite(&'static str, f64),
    #[error("--view-distance must be positive")]
    ViewDistance(f64),
    #[error("--fov must be in (0, 180) degrees")]
    Fov(f64),
    #[error("the camera cannot look straight up or down (--view-theta 0 or 180)")]
    VerticalView,
}

impl SceneSpec {
    /// The defaults of `brtf render image`.
    pub const DEFAULT: SceneSpec = SceneSpec {
        scene: SceneKind::SpherePlane,
        light: LightSpec {
            kind: LightKind::Distant,
            theta: 40.0,
            phi: 210.0,
            apex: 0.53,
            lamp_distance: 6.0,
            lamp_radius: 0.5,
            irradiance: 1.0,
            background: 0.05,
        },
        view: ViewSpec {
            theta: 65.0,
            phi: 300.0,
            distance: 8.0,
            fov: 35.0,
            width: 480,
            height: 360,
        },
        settings: Settings {
            source_samples: 1,
            specular_samples: 1,
            diffuse_samples: 0,
            max_depth: 4,
        },
        direct_only: false,
    };

    /// Checks every number; the first problem found is returned.
    pub fn validate(&self) -> Result<(), SceneSpecError> {
        let (l, v) = (&self.light, &self.view);
        let pixels = v.width.checked_mul(v.height);
        if v.width == 0 || v.height == 0 || pixels.is_none_or(|n| n > MAX_PIXELS) {
            return Err(SceneSpecError::ImageSize {
                width: v.width,
                height: v.height,
            });
        }
        if !(l.irradiance > 0.0 && l.irradiance.is_finite()) {
            return Err(SceneSpecError::Irradiance(l.irradiance));
        }
        for (name, x) in [
            ("light-theta", l.theta),
            ("light-phi", l.phi),
            ("view-theta", v.theta),
            ("view-phi", v.phi),
        ] {
            if !x.is_finite() {
                return Err(SceneSpecError::NotFinite(name, x));
            }
        }
        match l.kind {
            LightKind::Distant => {
                let a = 0.5 * l.apex.to_radians();
                if !(a > 0.0 && a < 1.5) {
                    return Err(SceneSpecError::LightApex(l.apex));
                }
            }
            LightKind::Sphere => {
                let (d, r) = (l.lamp_distance, l.lamp_radius);
                if !(r > 0.0 && d > r + BALL_RADIUS + 1.0 && d.is_finite()) {
                    return Err(SceneSpecError::Lamp {
                        distance: d,
                        radius: r,
                    });
                }
            }
        }
        if !(l.background >= 0.0 && l.background.is_finite()) {
            return Err(SceneSpecError::Background(l.background));
        }
        if !(v.distance > 0.0 && v.distance.is_finite()) {
            return Err(SceneSpecError::ViewDistance(v.distance));
        }
        if !(v.fov > 0.0 && v.fov < 180.0) {
            return Err(SceneSpecError::Fov(v.fov));
        }
        let look = -brtf_model::direction(v.theta, v.phi);
        if look.cross(DVec3::Z).length() < 1e-9 {
            return Err(SceneSpecError::VerticalView);
        }
        Ok(())
    }

    /// Unit vector from the origin towards the light.
    pub fn light_dir(&self) -> DVec3 {
        brtf_model::direction(self.light.theta, self.light.phi)
    }

    /// The source's radiance that gives the irradiance at the origin:
    /// `E = L π sin²a` (a: half the apex angle of the distant source, or
    /// the angular radius of the lamp, with `sin a ≈ r/d`).
    pub fn source_radiance(&self) -> f64 {
        let l = &self.light;
        let sin_a = match l.kind {
            LightKind::Distant => (0.5 * l.apex.to_radians()).sin(),
            LightKind::Sphere => l.lamp_radius / l.lamp_distance,
        };
        l.irradiance / (PI * sin_a.powi(2))
    }

    /// The background radiance (black with `direct_only`).
    pub fn background(&self) -> Rgb {
        if self.direct_only {
            [0.0; 3]
        } else {
            [self.light.background * self.light.irradiance / PI; 3]
        }
    }

    /// The integrator settings used (at least one source sample).
    pub fn settings(&self) -> Settings {
        if self.direct_only {
            Settings::direct_only()
        } else {
            Settings {
                source_samples: self.settings.source_samples.max(1),
                ..self.settings
            }
        }
    }

    /// The point the camera looks at.
    pub fn target(&self) -> DVec3 {
        match self.scene {
            SceneKind::Plane => DVec3::ZERO,
            _ => BALL_CENTER * 0.8,
        }
    }

    /// The camera.
    pub fn camera(&self) -> Camera {
        let v = &self.view;
        let target = self.target();
        let eye = target + brtf_model::direction(v.theta, v.phi) * v.distance;
        Camera::look_at(eye, target, v.fov, v.width as f64 / v.height as f64)
    }

    /// Picture options for this spec: its size and settings, with
    /// `samples` (at least 1) camera rays per pixel.
    pub fn image_options(&self, samples: u32, jitter: bool, seed: u64) -> ImageOptions {
        ImageOptions {
            width: self.view.width,
            height: self.view.height,
            samples: samples.max(1),
            jitter,
            seed,
            settings: self.settings(),
        }
    }

    /// Validates the spec and builds its scene, with `shader` on every
    /// surface, and its camera.
    pub fn build(&self, shader: Shader) -> Result<(Scene, Camera), SceneSpecError> {
        self.validate()?;
        let mut scene = Scene::new();
        let id = scene.add_shader(shader);
        if self.scene.has_floor() {
            scene.add(
                Shape::Disk {
                    center: DVec3::ZERO,
                    normal: DVec3::Z,
                    radius: FLOOR_RADIUS,
                },
                id,
            );
        }
        if self.scene.has_ball() {
            scene.add(
                Shape::Sphere {
                    center: BALL_CENTER,
                    radius: BALL_RADIUS,
                },
                id,
            );
        }
        let radiance = [self.source_radiance(); 3];
        let dir = self.light_dir();
        scene.sources.push(match self.light.kind {
            LightKind::Distant => Source::distant(dir, self.light.apex, radiance),
            LightKind::Sphere => Source::Sphere {
                center: dir * self.light.lamp_distance,
                radius: self.light.lamp_radius,
                radiance,
            },
        });
        scene.background = self.background();
        Ok((scene, self.camera()))
    }

    /// The scene as Radiance text. `material` is the material primitive's
    /// text, named [`MATERIAL_NAME`]; `name` is the file name (without
    /// extension) the comment's `rpict` line uses for the view and octree.
    pub fn radiance_text(&self, material: &str, name: &str) -> String {
        let mut s = format!(
            "# brtf render image --radiance: the scene brtf-trace rendered.\n\
             # rpict -vf {name}.vf -x {w} -y {h} -pa 0 -ab 0 -av 0 0 0 -st 1 -ps 1 -pj 0 {name}.oct\n\n{material}\n",
            w = self.view.width,
            h = self.view.height,
        );
        let m = MATERIAL_NAME;
        if self.scene.has_floor() {
            s += &format!("{m} ring floor\n0\n0\n8 0 0 0  0 0 1  0 {FLOOR_RADIUS}\n\n");
        }
        if self.scene.has_ball() {
            s += &format!(
                "{m} sphere ball\n0\n0\n4 {} {} {} {BALL_RADIUS}\n\n",
                BALL_CENTER.x, BALL_CENTER.y, BALL_CENTER.z
            );
        }
        let l = self.source_radiance();
        let dir = self.light_dir();
        match self.light.kind {
            LightKind::Distant => {
                s += &format!(
                    "void light sunlight\n0\n0\n3 {l} {l} {l}\n\nsunlight source sun\n0\n0\n4 {} {} {} {}\n\n",
                    dir.x, dir.y, dir.z, self.light.apex
                );
            }
            LightKind::Sphere => {
                let c = dir * self.light.lamp_distance;
                s += &format!(
                    "void light lamplight\n0\n0\n3 {l} {l} {l}\n\nlamplight sphere lamp\n0\n0\n4 {} {} {} {}\n\n",
                    c.x, c.y, c.z, self.light.lamp_radius
                );
            }
        }
        let background = self.background();
        if background.iter().any(|&b| b > 0.0) {
            let b = background[0];
            s += &format!(
                "# The constant background (seen by specular and ambient rays only).\n\
                 void glow skyglow\n0\n0\n4 {b} {b} {b} 0\n\nskyglow source sky\n0\n0\n4 0 0 1 360\n"
            );
        }
        s
    }
}

impl Default for SceneSpec {
    fn default() -> Self {
        SceneSpec::DEFAULT
    }
}
