//! brtf-trace: a minimal ray tracer (being built).
