//! Integration tests for brtf-gonio.
