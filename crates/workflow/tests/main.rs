//! Tests of brtf-workflow, one module per area.

mod info;
