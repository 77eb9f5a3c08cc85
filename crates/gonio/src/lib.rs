//! brtf-gonio: gonio-photometer measurement files.
//!
//! Reads and writes the two text formats of `../shared/spec/gonio-formats.md` — the
//! Fraunhofer ISE `.mpc` and the pab-opto "Mountain" (pgII) format — into
//! one data model, [`Measurement`], and computes what a fitter and a human
//! need from it: per-sample solid angles, data-side hemispherical
//! integrals, selections and a [`Summary`].
//!
//! # Conventions
//!
//! - **Angles** are degrees everywhere in this crate's interface. θ is
//!   measured from the front surface normal: θ ≤ 90° is the front
//!   (reflection) hemisphere, θ > 90° the back (transmission) one. φ is
//!   counter-clockwise seen from the front. Readers accept φ in `[0, 360)`
//!   or `(−180, 180]` and **normalise it to `[0, 360)`**.
//! - **Directions** point away from the surface: the incidence (θ_in, φ_in)
//!   points towards the light, a sample (θ_out, φ_out) towards the
//!   detector; as vectors `(sinθ cosφ, sinθ sinφ, cosθ)` with z the front
//!   normal ([`Sample::direction`], [`Measurement::incident_direction`]).
//!   The mirror direction of (θ_in, φ_in) is (θ_in, φ_in + 180°).
//! - **Quantities** ([`Quantity`]): BSDF in 1/sr without cosine; DSF =
//!   BSDF × |cos θ_out|; raw detector signal ∝ DSF with an unknown scale
//!   (the beam integral). Conversions are explicit ([`convert`]).
//! - **Not available**: the files' `9.9e+37` sentinel is stored as NaN,
//!   counted ([`Measurement::count_unavailable`]) and written back as
//!   `9.9e+37`. A literal `nan`/`inf` in a file is an error.
//! - **Solid angles** ([`solid_angle`]): the file's Voronoi cell sizes when
//!   present, otherwise equal-area planar Voronoi cells computed from the
//!   directions.
//!
//! # Example
//!
//! ```
//! let text = "#intheta 30\n#inphi 0\n#format: theta phi BSDF\n\
//!             30 180 2.5\n10 0 0.3\n";
//! let m = brtf_gonio::read_str(text, "example.txt").unwrap();
//! assert_eq!(m.incidence.theta_deg, 30.0);
//! assert_eq!(m.front_peak().unwrap().phi_deg, 180.0);
//! let dsf = m.to_dsf().unwrap().measurement;
//! assert!((dsf.samples[0].values[0] - 2.5 * 30f64.to_radians().cos()).abs() < 1e-12);
//! ```

mod aperture;
mod convert;
mod error;
mod integral;
pub mod klems;
mod measurement;
mod read;
mod select;
pub mod shadow;
mod solid_angle;
mod summary;
pub mod synth;
mod synth_limits;
mod write;

pub use aperture::{Apertures, DETECTOR_APERTURE_KEY, SOURCE_APERTURE_KEY};
pub use convert::{Converted, GRAZING_COS_LIMIT};
pub use error::{ConvertError, KlemsProblem, ParseErrorKind, ReadError, TreeProblem, WriteError};
pub use integral::{HemisphereIntegral, hemispherical_integral};
pub use measurement::{
    BeamReference, Channels, Hemisphere, Hemispheres, Incidence, IncidenceOrigin, Measurement,
    MpcColumns, Quantity, SENTINEL, SENTINEL_TEXT, SENTINEL_THRESHOLD, Sample, SourceFormat,
    direction_from_degrees, normalize_phi_deg,
};
pub use read::{
    detect_format, incidence_from_file_name, is_xml, read_bytes, read_bytes_as, read_path,
    read_path_as, read_sample_name, read_sample_name_at, read_str,
};
pub use select::{
    DEFAULT_THETA_CAP_DEG, DETECTED_SHADOW, Gate, GateContext, PGII_HOLDER_BAND, Selection,
};
pub use solid_angle::{
    DISK_RADIUS, DirectionLayout, SolidAngleSource, SolidAngles, compute_solid_angles,
    detect_layout, disk_voronoi_areas, project, reference_disk_voronoi_areas, solid_angles,
    voronoi_solid_angles,
};
pub use summary::{HemisphereSummary, Peak, Summary};
pub use synth_limits::MAX_SYNTH_SAMPLES;
pub use write::{to_mountain_string, to_mpc_string, write_mountain, write_mpc, write_path};
