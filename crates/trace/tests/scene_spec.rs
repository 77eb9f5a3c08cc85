//! The picture scene of `brtf render image` ([`SceneSpec`]): validation,
//! the built scene and camera, and the Radiance text (compared, byte for
//! byte, with what `brtf render image --radiance` wrote before the scene
//! moved into brtf-trace), and the gonio-photometer's direction grid and
//! apertures.

use crate::common::{mat, shader_of};
use brtf_model::{EvalOptions, MaterialKind};
use brtf_trace::{Aperture, GonioError, GonioSetup, aperture_solid_angle, grid};
use brtf_trace::{BALL_CENTER, FLOOR_RADIUS};
use brtf_trace::{
    LightKind, SceneKind, SceneSpec, SceneSpecError, Settings, Shader, Shape, Source,
};

fn shader() -> Shader {
    let m = mat(MaterialKind::Plastic, &[0.6, 0.5, 0.4, 0.05, 0.1]);
    shader_of(&m, &EvalOptions::default())
}

/// The defaults at 16 × 12 pixels.
fn small() -> SceneSpec {
    let mut spec = SceneSpec::DEFAULT;
    spec.view.width = 16;
    spec.view.height = 12;
    spec
}

/// A sphere lamp over the plane alone, direct light only.
fn lamp_on_plane() -> SceneSpec {
    let mut spec = small();
    spec.scene = SceneKind::Plane;
    spec.light.kind = LightKind::Sphere;
    spec.direct_only = true;
    spec
}

/// The sphere alone, no background, the sun low in the south-east.
fn low_sun_on_sphere() -> SceneSpec {
    let mut spec = SceneSpec::DEFAULT;
    spec.scene = SceneKind::Sphere;
    spec.light.background = 0.0;
    spec.light.theta = 70.0;
    spec.light.phi = -30.0;
    spec.view.width = 10;
    spec.view.height = 12;
    spec
}

const METAL: &str = "void metal sample\n0\n0\n5 0.9 0.85 0.8 0.9 0.12\n";
const PLASTIC: &str = "void plastic sample\n0\n0\n5 0.7 0.2 0.15 0.05 0.08\n";
const TRANS: &str = "void trans sample\n0\n0\n7 0.8 0.8 0.75 0.03 0.15 0.5 0.3\n";

#[test]
fn radiance_text_is_unchanged() {
    assert_eq!(small().radiance_text(METAL, "p1"), P1);
    assert_eq!(lamp_on_plane().radiance_text(PLASTIC, "p2"), P2);
    assert_eq!(low_sun_on_sphere().radiance_text(TRANS, "p3"), P3);
}

#[test]
fn camera_view_is_unchanged() {
    assert_eq!(small().camera().view_options(), V1);
    assert_eq!(lamp_on_plane().camera().view_options(), V2);
    assert_eq!(low_sun_on_sphere().camera().view_options(), V3);
}

#[test]
fn built_scene_matches_the_spec() {
    let spec = small();
    let (scene, camera) = spec.build(shader()).unwrap();
    assert_eq!(camera, spec.camera());
    assert_eq!(scene.objects.len(), 2);
    assert_eq!(scene.shaders.len(), 1);
    assert!(matches!(
        scene.objects[0].shape,
        Shape::Disk { radius, .. } if radius == FLOOR_RADIUS
    ));
    assert!(matches!(
        scene.objects[1].shape,
        Shape::Sphere { center, .. } if center == BALL_CENTER
    ));
    // E = L π sin²a at the origin, normal to the sun.
    let Source::Distant {
        dir,
        half_angle,
        radiance,
    } = scene.sources[0]
    else {
        panic!("a distant source");
    };
    let e = radiance[0] * std::f64::consts::PI * half_angle.sin().powi(2);
    assert!((e - spec.light.irradiance).abs() < 1e-12);
    assert!((dir - spec.light_dir()).length() < 1e-12);
    let b = spec.light.background * spec.light.irradiance / std::f64::consts::PI;
    assert_eq!(scene.background, [b; 3]);
    let options = spec.image_options(0, true, 7);
    assert_eq!(
        (options.width, options.height, options.samples),
        (16, 12, 1)
    );
    assert_eq!(options.settings, Settings::default());

    let lamp = lamp_on_plane();
    let (scene, _) = lamp.build(shader()).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert!(matches!(scene.sources[0], Source::Sphere { radius, .. } if radius == 0.5));
    assert_eq!(scene.background, [0.0; 3]);
    assert_eq!(lamp.settings(), Settings::direct_only());

    let (scene, _) = low_sun_on_sphere().build(shader()).unwrap();
    assert_eq!(scene.objects.len(), 1);
    assert!(matches!(scene.objects[0].shape, Shape::Sphere { .. }));
}

#[test]
fn bad_numbers_are_rejected() {
    let check = |f: &dyn Fn(&mut SceneSpec), want: &str| {
        let mut spec = SceneSpec::DEFAULT;
        f(&mut spec);
        let err = spec.validate().unwrap_err();
        assert_eq!(err.to_string(), want, "{err:?}");
        assert_eq!(spec.build(shader()).unwrap_err().to_string(), want);
    };
    let size = "image size must be between 1×1 and 64 Mpixel";
    check(&|s| s.view.width = 0, size);
    check(&|s| s.view.height = 0, size);
    check(&|s| (s.view.width, s.view.height) = (8001, 8000), size);
    check(&|s| (s.view.width, s.view.height) = (usize::MAX, 2), size);
    check(
        &|s| s.light.irradiance = 0.0,
        "--irradiance must be positive",
    );
    check(
        &|s| s.light.irradiance = f64::NAN,
        "--irradiance must be positive",
    );
    check(
        &|s| s.light.irradiance = f64::INFINITY,
        "--irradiance must be positive",
    );
    let apex = "--light-apex must be in (0, 170) degrees";
    check(&|s| s.light.apex = 0.0, apex);
    check(&|s| s.light.apex = 172.0, apex);
    check(&|s| s.light.apex = f64::NAN, apex);
    let lamp = "the lamp must clear the sphere";
    let sphere = |s: &mut SceneSpec| s.light.kind = LightKind::Sphere;
    check(&|s| (sphere(s), s.light.lamp_distance = 2.4).1, lamp);
    check(&|s| (sphere(s), s.light.lamp_radius = 0.0).1, lamp);
    check(&|s| (sphere(s), s.light.lamp_radius = f64::NAN).1, lamp);
    check(
        &|s| (sphere(s), s.light.lamp_distance = f64::INFINITY).1,
        lamp,
    );
    check(
        &|s| s.light.theta = f64::NAN,
        "--light-theta must be a finite number",
    );
    check(
        &|s| s.view.phi = f64::INFINITY,
        "--view-phi must be a finite number",
    );
    let background = "--background must be a finite number ≥ 0";
    check(&|s| s.light.background = -0.1, background);
    check(&|s| s.light.background = f64::NAN, background);
    let distance = "--view-distance must be positive";
    check(&|s| s.view.distance = 0.0, distance);
    check(&|s| s.view.distance = f64::NAN, distance);
    check(&|s| s.view.fov = 180.0, "--fov must be in (0, 180) degrees");
    check(&|s| s.view.fov = 0.0, "--fov must be in (0, 180) degrees");
    let vertical = "the camera cannot look straight up or down (--view-theta 0 or 180)";
    check(&|s| s.view.theta = 0.0, vertical);
    check(&|s| s.view.theta = 180.0, vertical);
    // The limits themselves are fine; a distant light ignores the lamp.
    let mut spec = SceneSpec::DEFAULT;
    (spec.view.width, spec.view.height) = (8000, 8000);
    spec.light.lamp_radius = -1.0;
    spec.light.background = 0.0;
    spec.view.theta = 1.0;
    spec.validate().unwrap();
    spec.light.kind = LightKind::Sphere;
    let err = spec.validate().unwrap_err();
    assert!(matches!(err, SceneSpecError::Lamp { .. }), "{err:?}");
    spec.light.lamp_radius = 1.0;
    spec.validate().unwrap();
}

#[test]
fn grid_covers_the_hemispheres() {
    let front = grid(10.0, 45.0, false).unwrap();
    // θ = 0 once, then 8 azimuths for each of 10°..80°.
    assert_eq!(front.len(), 1 + 8 * 8);
    assert_eq!(front[0], (0.0, 0.0));
    assert_eq!(front[1], (10.0, 0.0));
    assert_eq!(front[8], (10.0, 315.0));
    assert_eq!(*front.last().unwrap(), (80.0, 315.0));
    let both = grid(10.0, 45.0, true).unwrap();
    assert_eq!(both.len(), 2 * front.len());
    assert_eq!(
        &both[..4],
        &[(0.0, 0.0), (180.0, 0.0), (10.0, 0.0), (170.0, 0.0)]
    );
    // A step that does not divide 360° is rounded to one that does.
    let odd = grid(85.0, 110.0, false).unwrap();
    assert_eq!(odd, [(0.0, 0.0), (85.0, 0.0), (85.0, 120.0), (85.0, 240.0)]);
    assert_eq!(grid(90.0, 500.0, false).unwrap(), [(0.0, 0.0)]);
}

#[test]
fn bad_grid_steps_are_errors() {
    for (dt, dp) in [
        (0.0, 15.0),
        (5.0, -1.0),
        (f64::NAN, 15.0),
        (5.0, f64::INFINITY),
    ] {
        let err = grid(dt, dp, false).unwrap_err();
        assert!(
            matches!(err, GonioError::GridStep { .. }),
            "{dt} {dp}: {err:?}"
        );
        assert_eq!(err.to_string(), "grid steps must be positive");
    }
    let err = grid(1e-9, 1e-9, true).unwrap_err();
    assert!(matches!(err, GonioError::GridSize { .. }), "{err:?}");
}

#[test]
fn apertures_from_omega_or_apex() {
    let src = Aperture::Source;
    assert_eq!(aperture_solid_angle(src, None, None), Ok(None));
    assert_eq!(aperture_solid_angle(src, Some(1e-3), None), Ok(Some(1e-3)));
    let w = aperture_solid_angle(Aperture::Detector, None, Some(2.0))
        .unwrap()
        .unwrap();
    assert_eq!(w, brtf_model::cone_solid_angle(2.0));
    let msg = |r: Result<Option<f64>, GonioError>| r.unwrap_err().to_string();
    assert_eq!(
        msg(aperture_solid_angle(src, Some(1.0), Some(1.0))),
        "give the source as --source-omega or --source-apex, not both"
    );
    assert_eq!(
        msg(aperture_solid_angle(Aperture::Detector, Some(-1.0), None)),
        "--detector-omega must be ≥ 0 sr"
    );
    assert_eq!(
        msg(aperture_solid_angle(src, None, Some(180.5))),
        "--source-apex must be between 0 and 180 degrees"
    );
    let mut setup = GonioSetup::new(30.0, 0.0);
    setup.validate().unwrap();
    setup.theta_in = 181.0;
    assert_eq!(
        setup.validate().unwrap_err().to_string(),
        "θ_in must be between 0 and 180 degrees"
    );
    setup.theta_in = 0.0;
    setup.detector_omega = f64::NAN;
    assert_eq!(setup.validate(), Err(GonioError::Omega(Aperture::Detector)));
}

// What `brtf render image --radiance` wrote for these specs (PREFIX p1,
// p2, p3) before the scene moved into brtf-trace.
const P1: &str = r#"# brtf render image --radiance: the scene brtf-trace rendered.
# rpict -vf p1.vf -x 16 -y 12 -pa 0 -ab 0 -av 0 0 0 -st 1 -ps 1 -pj 0 p1.oct

void metal sample
0
0
5 0.9 0.85 0.8 0.9 0.12

sample ring floor
0
0
8 0 0 0  0 0 1  0 6

sample sphere ball
0
0
4 0 0 1 1

void light sunlight
0
0
3 14880.13053430347 14880.13053430347 14880.13053430347

sunlight source sun
0
0
4 -0.5566703992264194 -0.32139380484326957 0.7660444431189781 0.53

# The constant background (seen by specular and ambient rays only).
void glow skyglow
0
0
4 0.015915494309189534 0.015915494309189534 0.015915494309189534 0

skyglow source sky
0
0
4 0 0 1 360
"#;
const P2: &str = r#"# brtf render image --radiance: the scene brtf-trace rendered.
# rpict -vf p2.vf -x 16 -y 12 -pa 0 -ab 0 -av 0 0 0 -st 1 -ps 1 -pj 0 p2.oct

void plastic sample
0
0
5 0.7 0.2 0.15 0.05 0.08

sample ring floor
0
0
8 0 0 0  0 0 1  0 6

void light lamplight
0
0
3 45.83662361046586 45.83662361046586 45.83662361046586

lamplight sphere lamp
0
0
4 -3.340022395358516 -1.9283628290596173 4.596266658713869 0.5

"#;
const P3: &str = r#"# brtf render image --radiance: the scene brtf-trace rendered.
# rpict -vf p3.vf -x 10 -y 12 -pa 0 -ab 0 -av 0 0 0 -st 1 -ps 1 -pj 0 p3.oct

void trans sample
0
0
7 0.8 0.8 0.75 0.03 0.15 0.5 0.3

sample sphere ball
0
0
4 0 0 1 1

void light sunlight
0
0
3 14880.13053430347 14880.13053430347 14880.13053430347

sunlight source sun
0
0
4 0.8137976813493738 -0.46984631039295416 0.3420201433256687 0.53

"#;
const V1: &str = "rview -vtv -vp 3.6252311481465993 -6.279084537771166 4.180946093925596 -vd -0.4531538935183249 0.7848855672213958 -0.4226182617406995 -vu 0 0 1 -vh 35 -vv 26.60912789262675 -vo 0 -va 0 -vs 0 -vl 0";
const V2: &str = "rview -vtv -vp 3.6252311481465993 -6.279084537771166 3.3809460939255955 -vd -0.4531538935183249 0.7848855672213958 -0.42261826174069944 -vu 0 0 1 -vh 35 -vv 26.60912789262675 -vo 0 -va 0 -vs 0 -vl 0";
const V3: &str = "rview -vtv -vp 3.6252311481465993 -6.279084537771166 4.180946093925596 -vd -0.4531538935183249 0.7848855672213958 -0.4226182617406995 -vu 0 0 1 -vh 35 -vv 41.449129783002824 -vo 0 -va 0 -vs 0 -vl 0";
