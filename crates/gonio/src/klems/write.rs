//! The Klems BSDF XML writer.
//!
//! The layout follows the real files Radiance and WINDOW read (the two
//! fabrics in `../shared/data/lbnl-frads-klems-fabrics/`, `wrapBSDF`'s
//! template) and the element names and order of the BSDF schema v1.7.5:
//! `WindowElement` (namespace `http://windows.lbl.gov`, with its schema
//! location), `WindowElementType`, `FileType`, then `Optical/Layer` with
//! `Material` (`Name`, `Manufacturer`, `Thickness`, `DeviceType`),
//! `DataDefinition` (`Columns`, the basis with its blocks) and one
//! `WavelengthData` per band and direction. Values are written row by row
//! (one outgoing patch per line), `values[o * n + i]`, as Radiance reads
//! `Columns` data, each followed by a comma as WINDOW writes them
//! (pyWinCalc reads space-separated rows as one row: "Non-square matrix").

use std::fmt::Write;

use super::{KlemsBand, KlemsBasis, KlemsDirection};

/// The schema location written in the root element.
pub(super) const SCHEMA_LOCATION: &str = "http://windows.lbl.gov BSDF-v1.7.5.xsd";

/// The header of a written file.
#[derive(Debug, Clone, PartialEq)]
pub struct KlemsWriteHeader {
    /// `Name`.
    pub name: String,
    /// `Manufacturer`.
    pub manufacturer: String,
    /// `Thickness` in millimetres.
    pub thickness_mm: f64,
    /// `DeviceType` (WINDOW knows e.g. `Other`, `Venetian`, `Woven`).
    pub device_type: String,
    /// The thermal fields WINDOW and EnergyPlus read, when given.
    pub window: WindowFields,
    /// Lines of the leading XML comment (provenance, assumptions).
    pub comment: Vec<String>,
}

/// The optional `Material` fields of WINDOW's heat balance.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct WindowFields {
    /// `ThermalConductivity`, W/(m·K).
    pub conductivity: Option<f64>,
    /// `EmissivityFront`, `EmissivityBack` (WINDOW's sides: its front is
    /// Radiance's back).
    pub emissivity: Option<[f64; 2]>,
    /// `TIR`: the infrared transmittance.
    pub ir_transmittance: Option<f64>,
    /// `PermeabilityFactor`: the open fraction of the layer.
    pub permeability: Option<f64>,
}

impl WindowFields {
    /// Checks the ranges, naming the option: a conductivity > 0, the
    /// others in [0, 1], and emissivity + IR transmittance ≤ 1 on each
    /// side (what is neither is reflected).
    pub fn validate(&self) -> Result<(), String> {
        let fraction = |option: &str, v: f64| -> Result<(), String> {
            if (0.0..=1.0).contains(&v) {
                Ok(())
            } else {
                Err(format!("{option} {v}: out of range; allowed: 0 to 1"))
            }
        };
        if let Some(k) = self.conductivity
            && !(k.is_finite() && k > 0.0)
        {
            return Err(format!(
                "--conductivity {k}: out of range; allowed: > 0 W/(m·K)"
            ));
        }
        for e in self.emissivity.into_iter().flatten() {
            fraction("--emissivity", e)?;
        }
        if let Some(t) = self.ir_transmittance {
            fraction("--ir-transmittance", t)?;
            for e in self.emissivity.into_iter().flatten() {
                if e + t > 1.0 + 1e-12 {
                    return Err(format!(
                        "--emissivity {e} with --ir-transmittance {t}: their sum exceeds 1"
                    ));
                }
            }
        }
        if let Some(p) = self.permeability {
            fraction("--permeability", p)?;
        }
        Ok(())
    }

    /// The elements, in the order WINDOW writes them.
    fn elements(&self) -> Vec<(&'static str, f64)> {
        let mut out = Vec::new();
        out.extend(self.conductivity.map(|k| ("ThermalConductivity", k)));
        if let Some([front, back]) = self.emissivity {
            out.extend([("EmissivityFront", front), ("EmissivityBack", back)]);
        }
        out.extend(self.ir_transmittance.map(|t| ("TIR", t)));
        out.extend(self.permeability.map(|p| ("PermeabilityFactor", p)));
        out
    }
}

/// One matrix to write.
#[derive(Debug, Clone, PartialEq)]
pub struct KlemsWriteBlock {
    /// The band.
    pub band: KlemsBand,
    /// The direction.
    pub direction: KlemsDirection,
    /// `values[o * n + i]`, BSDF in 1/sr (n = the basis's patches).
    pub values: Vec<f64>,
}

/// Escapes text for element content and attribute values.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out += "&amp;",
            '<' => out += "&lt;",
            '>' => out += "&gt;",
            '"' => out += "&quot;",
            '\'' => out += "&apos;",
            c if c.is_control() && c != '\t' => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A comment line: `--` cannot appear inside an XML comment.
fn comment_line(text: &str) -> String {
    let mut line: String = text
        .chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect();
    while line.contains("--") {
        line = line.replace("--", "- -");
    }
    line.trim_end_matches('-').to_string()
}

/// The spectra WINDOW writes per band.
fn spectra(band: &KlemsBand) -> (&'static str, &'static str) {
    match band {
        KlemsBand::Visible => ("CIE Illuminant D65 1nm.ssp", "ASTM E308 1931 Y.dsp"),
        KlemsBand::CieX => ("CIE Illuminant D65 1nm.ssp", "ASTM E308 1931 X.dsp"),
        KlemsBand::CieZ => ("CIE Illuminant D65 1nm.ssp", "ASTM E308 1931 Z.dsp"),
        KlemsBand::Solar | KlemsBand::Other(_) => ("ISO8859-1", "None"),
    }
}

/// A number as the matrix text: 6 significant digits (`%.6g`-like),
/// negative zero and tiny negatives written as 0.
fn value_text(v: f64, out: &mut String) {
    if !v.is_finite() || v <= 0.0 {
        out.push('0');
        return;
    }
    let _ = write!(out, "{v:.5e}");
}

/// The whole file. Every block must hold n² values for the basis's n
/// patches (checked: a wrong count is a caller's bug and returns an error
/// naming the block).
pub fn to_klems_xml(
    header: &KlemsWriteHeader,
    basis: &KlemsBasis,
    blocks: &[KlemsWriteBlock],
) -> Result<String, String> {
    let n = basis.len();
    for b in blocks {
        if b.values.len() != n * n {
            return Err(format!(
                "{} {}: {} values for a {n}-patch basis (needs {})",
                b.band,
                b.direction,
                b.values.len(),
                n * n
            ));
        }
    }
    let mut o = String::with_capacity(blocks.len() * n * n * 12 + 8192);
    o += "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
    if !header.comment.is_empty() {
        o += "<!--\n";
        for line in &header.comment {
            let _ = writeln!(o, "  {}", comment_line(line));
        }
        o += "-->\n";
    }
    let _ = writeln!(
        o,
        "<WindowElement xmlns=\"http://windows.lbl.gov\" \
         xmlns:xsi=\"http://www.w3.org/2001/XMLSchema-instance\" \
         xsi:schemaLocation=\"{SCHEMA_LOCATION}\">"
    );
    o += "<WindowElementType>System</WindowElementType>\n";
    o += "<FileType>BSDF</FileType>\n";
    o += "<Optical>\n<Layer>\n\t<Material>\n";
    let _ = writeln!(o, "\t\t<Name>{}</Name>", escape(&header.name));
    let _ = writeln!(
        o,
        "\t\t<Manufacturer>{}</Manufacturer>",
        escape(&header.manufacturer)
    );
    let _ = writeln!(
        o,
        "\t\t<Thickness unit=\"Millimeter\">{}</Thickness>",
        header.thickness_mm
    );
    let _ = writeln!(
        o,
        "\t\t<DeviceType>{}</DeviceType>",
        escape(&header.device_type)
    );
    for (element, value) in header.window.elements() {
        let _ = writeln!(o, "\t\t<{element}>{value}</{element}>");
    }
    o += "\t</Material>\n";
    o += "\t<DataDefinition>\n\t\t<IncidentDataStructure>Columns</IncidentDataStructure>\n";
    o += "\t\t<AngleBasis>\n";
    let _ = writeln!(
        o,
        "\t\t\t<AngleBasisName>{}</AngleBasisName>",
        escape(&basis.name)
    );
    for ring in &basis.rings {
        let _ = write!(
            o,
            "\t\t\t<AngleBasisBlock>\n\t\t\t\t<Theta>{}</Theta>\n\t\t\t\t<nPhis>{}</nPhis>\n\
             \t\t\t\t<ThetaBounds>\n\t\t\t\t\t<LowerTheta>{}</LowerTheta>\n\
             \t\t\t\t\t<UpperTheta>{}</UpperTheta>\n\t\t\t\t</ThetaBounds>\n\
             \t\t\t</AngleBasisBlock>\n",
            ring.theta_deg, ring.n_phis, ring.lower_theta_deg, ring.upper_theta_deg
        );
    }
    o += "\t\t</AngleBasis>\n\t</DataDefinition>\n";
    let basis_name = escape(&basis.name);
    for b in blocks {
        let (source, detector) = spectra(&b.band);
        o += "\t<WavelengthData>\n\t\t<LayerNumber>System</LayerNumber>\n";
        let _ = writeln!(
            o,
            "\t\t<Wavelength unit=\"Integral\">{}</Wavelength>",
            escape(b.band.name())
        );
        let _ = writeln!(o, "\t\t<SourceSpectrum>{source}</SourceSpectrum>");
        let _ = writeln!(o, "\t\t<DetectorSpectrum>{detector}</DetectorSpectrum>");
        o += "\t\t<WavelengthDataBlock>\n";
        let _ = writeln!(
            o,
            "\t\t\t<WavelengthDataDirection>{}</WavelengthDataDirection>",
            b.direction.name()
        );
        let _ = writeln!(o, "\t\t\t<ColumnAngleBasis>{basis_name}</ColumnAngleBasis>");
        let _ = writeln!(o, "\t\t\t<RowAngleBasis>{basis_name}</RowAngleBasis>");
        // wrapBSDF writes BTDF for reflection too; readers go by the direction.
        o += "\t\t\t<ScatteringDataType>BTDF</ScatteringDataType>\n";
        o += "\t\t\t<ScatteringData>\n";
        for row in b.values.chunks_exact(n) {
            for (i, &v) in row.iter().enumerate() {
                if i > 0 {
                    o.push(' ');
                }
                value_text(v, &mut o);
                o.push(',');
            }
            o.push('\n');
        }
        o += "\t\t\t</ScatteringData>\n\t\t</WavelengthDataBlock>\n\t</WavelengthData>\n";
    }
    o += "</Layer>\n</Optical>\n</WindowElement>\n";
    Ok(o)
}

impl super::KlemsBsdf {
    /// The file as the writer writes it ([`to_klems_xml`]): every matrix
    /// in file order, the header's `Material` fields, `comment` leading.
    /// The writer has room for the header's thermal fields only
    /// ([`WindowFields`]); a missing or unreadable thickness is written as
    /// 1 mm (`brtf export`'s default). Both are said in the comment.
    pub fn to_xml(&self, mut comment: Vec<String>) -> Result<String, String> {
        let h = &self.header;
        let mut window = WindowFields::default();
        let mut front_back = [None, None];
        let mut dropped = Vec::new();
        for (key, value) in &h.other {
            let number = value.trim().parse::<f64>().ok().filter(|v| v.is_finite());
            match (key.as_str(), number) {
                ("ThermalConductivity", Some(v)) => window.conductivity = Some(v),
                ("EmissivityFront", Some(v)) => front_back[0] = Some(v),
                ("EmissivityBack", Some(v)) => front_back[1] = Some(v),
                ("TIR", Some(v)) => window.ir_transmittance = Some(v),
                ("PermeabilityFactor", Some(v)) => window.permeability = Some(v),
                _ => dropped.push(format!("{key} {value}")),
            }
        }
        if let [Some(front), Some(back)] = front_back {
            window.emissivity = Some([front, back]);
        } else {
            let one = front_back.iter().zip(["EmissivityFront", "EmissivityBack"]);
            dropped.extend(one.filter_map(|(v, k)| v.map(|v| format!("{k} {v} (alone)"))));
        }
        if !dropped.is_empty() {
            comment.push(format!(
                "Material fields of {} not written: {}.",
                self.source,
                dropped.join(", ")
            ));
        }
        let thickness_mm = h.thickness_mm().unwrap_or_else(|| {
            comment.push(format!(
                "{}: no thickness in millimetres; written as 1 mm.",
                self.source
            ));
            1.0
        });
        let header = KlemsWriteHeader {
            name: h.name.clone().unwrap_or_default(),
            manufacturer: h.manufacturer.clone().unwrap_or_default(),
            thickness_mm,
            device_type: h.device_type.clone().unwrap_or_else(|| "Other".into()),
            window,
            comment,
        };
        to_klems_xml(&header, &self.basis, &self.write_blocks())
    }

    /// Every matrix as the writer takes it, in file order.
    pub fn write_blocks(&self) -> Vec<KlemsWriteBlock> {
        self.matrices
            .iter()
            .map(|m| KlemsWriteBlock {
                band: m.band.clone(),
                direction: m.direction,
                values: m.values.clone(),
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn window_fields_are_checked() {
        let ok = WindowFields {
            conductivity: Some(0.15),
            emissivity: Some([0.8, 0.7]),
            ir_transmittance: Some(0.2),
            permeability: Some(0.0),
        };
        assert!(ok.validate().is_ok());
        for bad in [
            WindowFields {
                conductivity: Some(0.0),
                ..ok
            },
            WindowFields {
                emissivity: Some([1.2, 0.5]),
                ..ok
            },
            WindowFields {
                ir_transmittance: Some(0.3),
                ..ok
            },
            WindowFields {
                permeability: Some(-0.1),
                ..ok
            },
            WindowFields {
                permeability: Some(f64::NAN),
                ..ok
            },
        ] {
            let err = bad.validate().unwrap_err();
            assert!(err.starts_with("--"), "{err}");
        }
    }

    #[test]
    fn written_files_read_back_with_their_header_and_values() {
        let basis = KlemsBasis::built_in("LBNL/Klems Quarter").unwrap();
        let n = basis.len();
        let values: Vec<f64> = (0..n * n).map(|k| 0.001 * k as f64 + 0.5).collect();
        let header = KlemsWriteHeader {
            name: "a <test> & 'b'".into(),
            manufacturer: "brtf".into(),
            thickness_mm: 1.5,
            device_type: "Other".into(),
            window: WindowFields {
                conductivity: Some(0.15),
                emissivity: Some([0.8, 0.7]),
                ir_transmittance: Some(0.1),
                permeability: Some(0.05),
            },
            comment: vec!["made -- by a test".into()],
        };
        let blocks = vec![
            KlemsWriteBlock {
                band: KlemsBand::Visible,
                direction: KlemsDirection::ReflectionBack,
                values: values.clone(),
            },
            KlemsWriteBlock {
                band: KlemsBand::Solar,
                direction: KlemsDirection::ReflectionBack,
                values: values.clone(),
            },
        ];
        let text = to_klems_xml(&header, &basis, &blocks).unwrap();
        let read = super::super::read_str(&text, "test.xml").unwrap();
        assert_eq!(read.header.name.as_deref(), Some("a <test> & 'b'"));
        assert_eq!(read.header.thickness_mm(), Some(1.5));
        assert_eq!(read.header.file_type.as_deref(), Some("BSDF"));
        let fields: Vec<(&str, &str)> = read
            .header
            .other
            .iter()
            .map(|(k, v)| (k.as_str(), v.as_str()))
            .collect();
        assert_eq!(
            fields,
            [
                ("ThermalConductivity", "0.15"),
                ("EmissivityFront", "0.8"),
                ("EmissivityBack", "0.7"),
                ("TIR", "0.1"),
                ("PermeabilityFactor", "0.05")
            ]
        );
        assert_eq!(read.bands(), vec![KlemsBand::Visible, KlemsBand::Solar]);
        let m = read
            .matrix(&KlemsBand::Visible, KlemsDirection::ReflectionBack)
            .unwrap();
        for (a, b) in m.values.iter().zip(&values) {
            assert!((a - b).abs() <= 1e-5 * b, "{a} {b}");
        }
        // Written again from what was read: the same file, comment aside.
        let again = read.to_xml(vec!["made -- by a test".into()]).unwrap();
        assert_eq!(again, text);
        let mut short = blocks[0].clone();
        short.values.pop();
        assert!(to_klems_xml(&header, &basis, &[short]).is_err());
    }
}
