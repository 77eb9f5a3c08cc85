//! Klems BSDF XML (the LBNL / WINDOW format Radiance reads and writes).
//!
//! A Klems file holds, per wavelength band and per direction
//! (`Transmission Front`, …), a square matrix of patch-averaged BSDF
//! values in 1/sr: column i is one incident patch, row o one outgoing
//! patch of a [`KlemsBasis`]. This module owns the typed file
//! ([`KlemsBsdf`]), its totals, the conversion to per-incidence
//! [`Measurement`]s and the summary `brtf info` prints ([`KlemsInfo`]).
//! The reader is [`read_path`] / [`read_str`]; `docs/klems.md` gives the
//! conventions.
//!
//! # Sides
//!
//! WINDOW's "front" is Radiance's back (−z). Light arriving from Radiance's
//! front (+z, [`Side::Front`]) uses the `Reflection Back` and
//! `Transmission Back` blocks; light from −z ([`Side::Back`]) the `Front`
//! blocks. Incident patch (θ, φ) is the direction of travel, so the source
//! sits at φ + 180°; outgoing patch (θ, φ) points at (θ, φ), on the
//! reflection or the transmission side.

mod basis;
mod model_matrix;
mod read;
pub mod ttree;
mod write;

use std::fmt;

use serde::Serialize;

use crate::measurement::{
    Channels, Incidence, IncidenceOrigin, Measurement, Quantity, Sample, SourceFormat,
};

pub use basis::{BasisSize, KlemsBasis, KlemsPatch, KlemsRing};
pub use model_matrix::{
    DEFAULT_SAMPLES, SampleOptions, SideMatrices, band_values, light_vector, side_matrices,
};
pub use read::{read_any_bytes, read_any_path, read_bytes, read_path, read_str};
pub use ttree::{TensorTree, TreeInfo, TreeRank};

/// A BSDF XML file of either kind.
#[derive(Clone, Debug, PartialEq)]
pub enum BsdfXml {
    /// Klems matrices (`Columns` or `Rows`).
    Klems(KlemsBsdf),
    /// A tensor tree (`TensorTree3` or `TensorTree4`).
    TensorTree(TensorTree),
}

impl BsdfXml {
    /// The `Material` header.
    pub fn header(&self) -> &KlemsHeader {
        match self {
            BsdfXml::Klems(b) => &b.header,
            BsdfXml::TensorTree(t) => &t.header,
        }
    }

    /// The sides with Visible data, front first.
    pub fn sides_present(&self) -> Vec<Side> {
        match self {
            BsdfXml::Klems(b) => b.sides_present(),
            BsdfXml::TensorTree(t) => t.sides_present(),
        }
    }
}
pub use write::{KlemsWriteBlock, KlemsWriteHeader, WindowFields, to_klems_xml};

/// Values below this are refused; values between it and 0 read as 0.
pub const NEGATIVE_LIMIT: f64 = -1e-3;

/// The four `WavelengthDataDirection`s.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum KlemsDirection {
    /// `Transmission Front`: Radiance's `tb`, light arriving from −z.
    TransmissionFront,
    /// `Transmission Back`: Radiance's `tf`, light arriving from +z.
    TransmissionBack,
    /// `Reflection Front`: Radiance's `rb`.
    ReflectionFront,
    /// `Reflection Back`: Radiance's `rf`.
    ReflectionBack,
}

impl KlemsDirection {
    /// All four, in the order WINDOW writes them.
    pub const ALL: [KlemsDirection; 4] = [
        KlemsDirection::TransmissionFront,
        KlemsDirection::TransmissionBack,
        KlemsDirection::ReflectionFront,
        KlemsDirection::ReflectionBack,
    ];

    /// The file's spelling.
    pub fn name(self) -> &'static str {
        match self {
            KlemsDirection::TransmissionFront => "Transmission Front",
            KlemsDirection::TransmissionBack => "Transmission Back",
            KlemsDirection::ReflectionFront => "Reflection Front",
            KlemsDirection::ReflectionBack => "Reflection Back",
        }
    }

    /// From the file's text (case and blanks between words ignored).
    pub fn parse(text: &str) -> Option<Self> {
        let words: Vec<String> = text
            .split_whitespace()
            .map(str::to_ascii_lowercase)
            .collect();
        let words: Vec<&str> = words.iter().map(String::as_str).collect();
        Some(match words.as_slice() {
            ["transmission", "front"] => KlemsDirection::TransmissionFront,
            ["transmission", "back"] => KlemsDirection::TransmissionBack,
            ["reflection", "front"] => KlemsDirection::ReflectionFront,
            ["reflection", "back"] => KlemsDirection::ReflectionBack,
            _ => return None,
        })
    }

    /// Radiance's component name: `tb`, `tf`, `rb` or `rf`.
    pub fn radiance_component(self) -> &'static str {
        match self {
            KlemsDirection::TransmissionFront => "tb",
            KlemsDirection::TransmissionBack => "tf",
            KlemsDirection::ReflectionFront => "rb",
            KlemsDirection::ReflectionBack => "rf",
        }
    }

    /// The Radiance side the light arrives from.
    pub fn incident_side(self) -> Side {
        match self {
            KlemsDirection::TransmissionBack | KlemsDirection::ReflectionBack => Side::Front,
            KlemsDirection::TransmissionFront | KlemsDirection::ReflectionFront => Side::Back,
        }
    }

    /// True for the transmission blocks.
    pub fn is_transmission(self) -> bool {
        matches!(
            self,
            KlemsDirection::TransmissionFront | KlemsDirection::TransmissionBack
        )
    }
}

impl fmt::Display for KlemsDirection {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// Radiance's side the light arrives from: front = +z, back = −z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Side {
    /// Light from +z (Radiance's front, WINDOW's back): `rf`, `tf`.
    Front,
    /// Light from −z (Radiance's back, WINDOW's front): `rb`, `tb`.
    Back,
}

impl Side {
    /// Both sides.
    pub const BOTH: [Side; 2] = [Side::Front, Side::Back];

    /// The reflection block for light from this side.
    pub fn reflection(self) -> KlemsDirection {
        match self {
            Side::Front => KlemsDirection::ReflectionBack,
            Side::Back => KlemsDirection::ReflectionFront,
        }
    }

    /// The transmission block for light from this side.
    pub fn transmission(self) -> KlemsDirection {
        match self {
            Side::Front => KlemsDirection::TransmissionBack,
            Side::Back => KlemsDirection::TransmissionFront,
        }
    }

    /// `front` or `back`.
    pub fn name(self) -> &'static str {
        brtf_model::OptionWords::word(self)
    }

    /// A polar angle θ (0-90° from this side's normal) in brtf's frame,
    /// where θ is measured from the front normal (+z).
    pub fn theta_in_frame(self, theta_deg: f64) -> f64 {
        match self {
            Side::Front => theta_deg,
            Side::Back => 180.0 - theta_deg,
        }
    }

    /// The other side.
    pub fn opposite(self) -> Side {
        match self {
            Side::Front => Side::Back,
            Side::Back => Side::Front,
        }
    }
}

brtf_model::option_words!(Side { Front => "front", Back => "back" });

/// The sides a Klems fit takes: one, or both (each its own fit).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Sides {
    /// Light from +z only.
    Front,
    /// Light from −z only.
    Back,
    /// Both sides.
    #[default]
    Both,
}

brtf_model::option_words!(Sides { Front => "front", Back => "back", Both => "both" });

impl From<Side> for Sides {
    fn from(side: Side) -> Sides {
        match side {
            Side::Front => Sides::Front,
            Side::Back => Sides::Back,
        }
    }
}

impl Sides {
    /// The sides, front first.
    pub fn sides(self) -> Vec<Side> {
        match self {
            Sides::Front => vec![Side::Front],
            Sides::Back => vec![Side::Back],
            Sides::Both => Side::BOTH.to_vec(),
        }
    }
}

/// A `Wavelength` band.
#[derive(Clone, Debug, PartialEq, Eq, Hash, Serialize, PartialOrd, Ord)]
#[serde(rename_all = "snake_case")]
pub enum KlemsBand {
    /// `Visible`: photopic, CIE-Y. What Radiance renders with.
    Visible,
    /// `CIE-X`.
    CieX,
    /// `CIE-Z`.
    CieZ,
    /// `Solar`: kept, but Radiance ignores it.
    Solar,
    /// Any other band, as the file names it.
    Other(String),
}

impl KlemsBand {
    /// From the file's `Wavelength` text.
    pub fn parse(text: &str) -> Self {
        let t = text.trim();
        if t.eq_ignore_ascii_case("visible") {
            KlemsBand::Visible
        } else if t.eq_ignore_ascii_case("cie-x") {
            KlemsBand::CieX
        } else if t.eq_ignore_ascii_case("cie-z") {
            KlemsBand::CieZ
        } else if t.eq_ignore_ascii_case("solar") {
            KlemsBand::Solar
        } else {
            KlemsBand::Other(t.to_string())
        }
    }

    /// The file's spelling.
    pub fn name(&self) -> &str {
        match self {
            KlemsBand::Visible => "Visible",
            KlemsBand::CieX => "CIE-X",
            KlemsBand::CieZ => "CIE-Z",
            KlemsBand::Solar => "Solar",
            KlemsBand::Other(name) => name,
        }
    }
}

impl fmt::Display for KlemsBand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The `Material` header fields (text as written, trimmed; `None` when the
/// element is absent or empty).
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct KlemsHeader {
    /// `FileType` (`BSDF`), optional.
    pub file_type: Option<String>,
    /// `WindowElementType`, e.g. `System`.
    pub window_element_type: Option<String>,
    /// `Manufacturer`.
    pub manufacturer: Option<String>,
    /// `Name`.
    pub name: Option<String>,
    /// `Thickness` as written.
    pub thickness: Option<String>,
    /// The `unit` attribute of `Thickness`, e.g. `Millimeter`.
    pub thickness_unit: Option<String>,
    /// `DeviceType`, e.g. `Other`.
    pub device_type: Option<String>,
    /// Every other non-empty `Material` child, in file order.
    pub other: Vec<(String, String)>,
}

impl KlemsHeader {
    /// The thickness in millimetres, when given as a number in a known unit.
    pub fn thickness_mm(&self) -> Option<f64> {
        let value: f64 = self.thickness.as_deref()?.trim().parse().ok()?;
        let scale = match self.thickness_unit.as_deref().map(str::to_ascii_lowercase) {
            None => 1.0,
            Some(u) if u == "millimeter" || u == "millimetre" || u == "mm" => 1.0,
            Some(u) if u == "meter" || u == "metre" || u == "m" => 1000.0,
            Some(u) if u == "centimeter" || u == "centimetre" || u == "cm" => 10.0,
            Some(u) if u == "inch" || u == "in" => 25.4,
            Some(_) => return None,
        };
        value.is_finite().then_some(value * scale)
    }
}

/// One matrix: a band, a direction and N × N patch-averaged BSDF values.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KlemsMatrix {
    /// The band.
    pub band: KlemsBand,
    /// The direction.
    pub direction: KlemsDirection,
    /// The number of patches N.
    pub n: usize,
    /// Row-major by outgoing patch: `values[o * n + i]` is the BSDF from
    /// incident patch i to outgoing patch o, 1/sr (Radiance's layout).
    #[serde(skip)]
    pub values: Vec<f64>,
    /// Values between −1e-3 and 0 that were read as 0, as Radiance does.
    pub clipped_negative: usize,
    /// The line of the `ScatteringData` element.
    pub line: usize,
}

impl KlemsMatrix {
    /// BSDF from incident patch `incident` to outgoing patch `outgoing`.
    /// Panics when either index is not below `n` (a caller's bug; the
    /// file's content cannot cause it).
    pub fn value(&self, outgoing: usize, incident: usize) -> f64 {
        self.values[outgoing * self.n + incident]
    }

    /// The column totals H_i = Σ_o BSDF[o][i] Λ_o: the hemispherical
    /// reflectance or transmittance of each incident patch, as Radiance's
    /// libBSDF (and so `checkBSDF`) computes them. Row sums would be wrong.
    pub fn column_totals(&self, basis: &KlemsBasis) -> Vec<f64> {
        let lambda = basis.projected_solid_angles();
        let mut totals = vec![0.0; self.n];
        for (o, row) in self.values.chunks_exact(self.n).enumerate() {
            let weight = lambda.get(o).copied().unwrap_or(0.0);
            for (total, value) in totals.iter_mut().zip(row) {
                *total += value * weight;
            }
        }
        totals
    }
}

/// A Klems BSDF XML file, read.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KlemsBsdf {
    /// The file's display path.
    pub source: String,
    /// The header fields.
    pub header: KlemsHeader,
    /// `Columns` (column = incident patch) or `Rows` in the file; the
    /// matrices are stored the same way whichever it was.
    pub incident_data_structure: String,
    /// The basis of every matrix.
    pub basis: KlemsBasis,
    /// Every matrix, in file order.
    pub matrices: Vec<KlemsMatrix>,
}

impl KlemsBsdf {
    /// The sides with Visible data (front first): genBSDF and one side's
    /// export write one side only.
    pub fn sides_present(&self) -> Vec<Side> {
        Side::BOTH
            .into_iter()
            .filter(|&side| {
                self.matrices
                    .iter()
                    .any(|m| m.band == KlemsBand::Visible && m.direction.incident_side() == side)
            })
            .collect()
    }

    /// The matrix of `band` and `direction`, if the file has it.
    pub fn matrix(&self, band: &KlemsBand, direction: KlemsDirection) -> Option<&KlemsMatrix> {
        self.matrices
            .iter()
            .find(|m| &m.band == band && m.direction == direction)
    }

    /// The bands present, in file order, each once.
    pub fn bands(&self) -> Vec<KlemsBand> {
        let mut bands: Vec<KlemsBand> = Vec::new();
        for m in &self.matrices {
            if !bands.contains(&m.band) {
                bands.push(m.band.clone());
            }
        }
        bands
    }

    /// The directions present (in any band), in the order of
    /// [`KlemsDirection::ALL`].
    pub fn directions(&self) -> Vec<KlemsDirection> {
        KlemsDirection::ALL
            .into_iter()
            .filter(|d| self.matrices.iter().any(|m| m.direction == *d))
            .collect()
    }

    /// The column totals of `band`/`direction` (see
    /// [`KlemsMatrix::column_totals`]), or `None` when absent.
    pub fn column_totals(&self, band: &KlemsBand, direction: KlemsDirection) -> Option<Vec<f64>> {
        Some(self.matrix(band, direction)?.column_totals(&self.basis))
    }

    /// The incidence of incident patch `patch` lit from `side`, in brtf's
    /// convention (towards the source): θ_in on that side, φ_in = φ + 180°.
    pub fn incidence(&self, side: Side, patch: usize) -> Option<Incidence> {
        let p = self.basis.patch(patch)?;
        Some(Incidence::new(
            side.theta_in_frame(p.theta_deg),
            crate::normalize_phi_deg(p.phi_deg + 180.0),
        ))
    }

    /// ρ_dh and τ_dh of every incident patch lit from `side`, from the
    /// `band` column totals (`None` where the block is absent).
    pub fn hemispherical(&self, band: &KlemsBand, side: Side) -> Vec<PatchTotals> {
        let rho = self.column_totals(band, side.reflection());
        let tau = self.column_totals(band, side.transmission());
        (0..self.basis.len())
            .filter_map(|i| {
                let incidence = self.incidence(side, i)?;
                Some(PatchTotals {
                    side,
                    patch: i,
                    theta_in_deg: incidence.theta_deg,
                    phi_in_deg: incidence.phi_deg,
                    rho_dh: rho.as_ref().map(|t| t[i]),
                    tau_dh: tau.as_ref().map(|t| t[i]),
                })
            })
            .collect()
    }

    /// The channels [`to_measurements`](Self::to_measurements) gives: XYZ
    /// when CIE-X and CIE-Z come with every Visible block, else Y.
    pub fn channels(&self) -> Channels {
        let visible: Vec<KlemsDirection> = self
            .matrices
            .iter()
            .filter(|m| m.band == KlemsBand::Visible)
            .map(|m| m.direction)
            .collect();
        let has_colour = !visible.is_empty()
            && visible.iter().all(|&d| {
                self.matrix(&KlemsBand::CieX, d).is_some()
                    && self.matrix(&KlemsBand::CieZ, d).is_some()
            });
        if has_colour {
            Channels::Xyz
        } else {
            Channels::Y
        }
    }

    /// Each incident patch of each side with a Visible block becomes one
    /// [`Measurement`] ([`SourceFormat::KlemsXml`], quantity BSDF): one
    /// sample per outgoing patch at the patch centre, reflection on the
    /// side of the light and transmission on the other, valued
    /// BSDF[o][i], with `solid_angle_sr` = Λ_o / cos θ_centre(o) so that
    /// brtf's integrals (Σ value · |cos θ| · dΩ) give exactly the column
    /// totals. The values are patch averages, not point values: the
    /// format says so. Side front first, patches in basis order.
    pub fn to_measurements(&self) -> Vec<Measurement> {
        Side::BOTH
            .into_iter()
            .flat_map(|side| {
                (0..self.basis.len()).filter_map(move |i| self.measurement(side, i, false))
            })
            .collect()
    }

    /// Incident patch `patch` lit from `side` as one [`Measurement`] (see
    /// [`to_measurements`](Self::to_measurements)); `None` when the side
    /// has no Visible block or the patch does not exist. With
    /// `in_side_frame`, the back side is described mirrored (z → −z), as
    /// if it were a front: the light on +z, reflection on +z and
    /// transmission on −z. That is how a side is fitted on its own.
    pub fn measurement(
        &self,
        side: Side,
        patch: usize,
        in_side_frame: bool,
    ) -> Option<Measurement> {
        let channels = self.channels();
        let frame = |s: Side| {
            if in_side_frame && side == Side::Back {
                s.opposite()
            } else {
                s
            }
        };
        let blocks: Vec<(KlemsDirection, Side)> = [
            (side.reflection(), frame(side)),
            (side.transmission(), frame(side.opposite())),
        ]
        .into_iter()
        .filter(|(d, _)| self.matrix(&KlemsBand::Visible, *d).is_some())
        .collect();
        if blocks.is_empty() {
            return None;
        }
        let i = patch;
        let mut incidence = self.incidence(side, i)?;
        if in_side_frame {
            incidence.theta_deg = self.basis.patch(i)?.theta_deg;
        }
        let mut samples = Vec::with_capacity(blocks.len() * self.basis.len());
        for &(direction, sample_side) in &blocks {
            let value_of = |band: &KlemsBand, o: usize| {
                self.matrix(band, direction).map_or(0.0, |m| m.value(o, i))
            };
            for (o, patch) in self.basis.patches().iter().enumerate() {
                let values = match channels {
                    Channels::Y => [value_of(&KlemsBand::Visible, o), 0.0, 0.0],
                    Channels::Xyz => [
                        value_of(&KlemsBand::CieX, o),
                        value_of(&KlemsBand::Visible, o),
                        value_of(&KlemsBand::CieZ, o),
                    ],
                };
                samples.push(Sample {
                    theta_deg: sample_side.theta_in_frame(patch.theta_deg),
                    phi_deg: patch.phi_deg,
                    values,
                    solid_angle_sr: Some(patch.centre_weight_sr()),
                });
            }
        }
        let mut m = Measurement::new(
            SourceFormat::KlemsXml,
            incidence,
            Quantity::Bsdf,
            channels,
            samples,
        );
        m.sample_name = self.header.name.clone();
        m.incidence_origin = IncidenceOrigin::Header;
        let frame_note = if in_side_frame && side == Side::Back {
            ", described mirrored (light on +z)"
        } else {
            ""
        };
        m.header = vec![format!(
            "Klems patch averages: incident patch {i} of {} ({} patches), lit from the {side} (+z is front){frame_note}, from {}",
            self.basis.name,
            self.basis.len(),
            self.source
        )];
        Some(m)
    }

    /// The summary `brtf info` prints.
    pub fn info(&self) -> KlemsInfo {
        let totals_band = if self.matrices.iter().any(|m| m.band == KlemsBand::Visible) {
            KlemsBand::Visible
        } else {
            self.matrices
                .first()
                .map_or(KlemsBand::Visible, |m| m.band.clone())
        };
        let incidences = Side::BOTH
            .into_iter()
            .filter(|side| {
                self.matrix(&totals_band, side.reflection()).is_some()
                    || self.matrix(&totals_band, side.transmission()).is_some()
            })
            .flat_map(|side| self.hemispherical(&totals_band, side))
            .collect();
        KlemsInfo {
            format: "Klems BSDF XML".into(),
            manufacturer: self.header.manufacturer.clone(),
            name: self.header.name.clone(),
            thickness: self.header.thickness.clone(),
            thickness_unit: self.header.thickness_unit.clone(),
            device_type: self.header.device_type.clone(),
            material_fields: self.header.other.clone(),
            basis: self.basis.name.clone(),
            patches: self.basis.len(),
            incident_data_structure: self.incident_data_structure.clone(),
            bands: self.bands().iter().map(|b| b.name().to_string()).collect(),
            blocks: self
                .matrices
                .iter()
                .map(|m| BlockInfo {
                    band: m.band.name().to_string(),
                    direction: m.direction,
                    radiance_component: m.direction.radiance_component(),
                    light_from: m.direction.incident_side(),
                    clipped_negative: m.clipped_negative,
                })
                .collect(),
            totals_band: totals_band.name().to_string(),
            incidences,
        }
    }
}

/// ρ_dh and τ_dh of one incident patch lit from one side.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct PatchTotals {
    /// The side the light comes from.
    pub side: Side,
    /// The incident patch index in the basis.
    pub patch: usize,
    /// θ_in in brtf's frame (from +z; above 90° for light from the back).
    pub theta_in_deg: f64,
    /// φ_in towards the source, degrees.
    pub phi_in_deg: f64,
    /// Directional-hemispherical reflectance (column total).
    pub rho_dh: Option<f64>,
    /// Directional-hemispherical transmittance (column total).
    pub tau_dh: Option<f64>,
}

/// One matrix as `brtf info` lists it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct BlockInfo {
    /// The band.
    pub band: String,
    /// The direction.
    pub direction: KlemsDirection,
    /// Radiance's name for it.
    pub radiance_component: &'static str,
    /// Where the light arrives from, in Radiance's frame.
    pub light_from: Side,
    /// Values between −1e-3 and 0 read as 0.
    pub clipped_negative: usize,
}

/// What `brtf info file.xml` prints (text via `Display`, or JSON).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct KlemsInfo {
    /// Always `Klems BSDF XML`.
    pub format: String,
    /// `Manufacturer`.
    pub manufacturer: Option<String>,
    /// `Name`.
    pub name: Option<String>,
    /// `Thickness` as written.
    pub thickness: Option<String>,
    /// Its unit.
    pub thickness_unit: Option<String>,
    /// `DeviceType`.
    pub device_type: Option<String>,
    /// The other `Material` fields (`ThermalConductivity`, `EmissivityFront`,
    /// `PermeabilityFactor`, …), in file order.
    pub material_fields: Vec<(String, String)>,
    /// The basis name.
    pub basis: String,
    /// Its number of patches.
    pub patches: usize,
    /// `Columns` or `Rows`.
    pub incident_data_structure: String,
    /// The bands, in file order.
    pub bands: Vec<String>,
    /// Every matrix.
    pub blocks: Vec<BlockInfo>,
    /// The band the totals below come from (Visible when present).
    pub totals_band: String,
    /// Per side and incident patch: θ_in, φ_in, ρ_dh, τ_dh.
    pub incidences: Vec<PatchTotals>,
}

impl fmt::Display for KlemsInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let text = |v: &Option<String>| v.clone().unwrap_or_else(|| "(empty)".into());
        writeln!(f, "format        {}", self.format)?;
        writeln!(f, "name          {}", text(&self.name))?;
        writeln!(f, "manufacturer  {}", text(&self.manufacturer))?;
        let thickness = match (&self.thickness, &self.thickness_unit) {
            (Some(t), Some(u)) => format!("{t} {u}"),
            (Some(t), None) => t.clone(),
            (None, _) => "(empty)".into(),
        };
        writeln!(f, "thickness     {thickness}")?;
        writeln!(f, "device type   {}", text(&self.device_type))?;
        for (key, value) in &self.material_fields {
            writeln!(f, "  {key} {value}")?;
        }
        writeln!(
            f,
            "basis         {} ({} patches, {})",
            self.basis, self.patches, self.incident_data_structure
        )?;
        writeln!(f, "bands         {}", self.bands.join(", "))?;
        writeln!(f, "blocks")?;
        for b in &self.blocks {
            write!(
                f,
                "  {:<8} {:<19} Radiance {}, light from {} ({} side)",
                b.band,
                b.direction.name(),
                b.radiance_component,
                if b.light_from == Side::Front {
                    "+z"
                } else {
                    "-z"
                },
                b.light_from
            )?;
            if b.clipped_negative > 0 {
                write!(
                    f,
                    ", {} small negative values read as 0",
                    b.clipped_negative
                )?;
            }
            writeln!(f)?;
        }
        writeln!(
            f,
            "per incidence ({} column totals, sum_o BSDF[o][i] Lambda_o; theta_in > 90 = lit from the back)",
            self.totals_band
        )?;
        writeln!(f, "  side   patch  theta_in  phi_in   rho_dh   tau_dh")?;
        let number =
            |v: Option<f64>| v.map_or_else(|| "       -".to_string(), |v| format!("{v:8.4}"));
        for p in &self.incidences {
            writeln!(
                f,
                "  {:<5} {:>6} {:>9.2} {:>7.2} {} {}",
                p.side.name(),
                p.patch,
                p.theta_in_deg,
                p.phi_in_deg,
                number(p.rho_dh),
                number(p.tau_dh)
            )?;
        }
        Ok(())
    }
}

/// True when `path` looks like a Klems BSDF XML file: an `.xml` extension,
/// or a first non-blank character `<` (gonio text files never start so).
/// Unreadable files give `false`; the reader then reports the error.
pub fn is_klems_file(path: &std::path::Path) -> bool {
    if path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("xml"))
    {
        return true;
    }
    use std::io::Read;
    let mut head = [0u8; 512];
    let Ok(mut file) = std::fs::File::open(path) else {
        return false;
    };
    let n = file.read(&mut head).unwrap_or(0);
    crate::read::is_xml(&head[..n])
}
