//! Serialises a material type as its Radiance name (`#[serde(with)]`).

use brtf_model::MaterialKind;
use serde::{Deserialize, Deserializer, Serializer};

pub(crate) fn serialize<S: Serializer>(k: &MaterialKind, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_str(k.name())
}

pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<MaterialKind, D::Error> {
    String::deserialize(d)?
        .parse()
        .map_err(serde::de::Error::custom)
}
