//! brtf-gonio
