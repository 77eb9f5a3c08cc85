//! Tests of brtf-workflow.
