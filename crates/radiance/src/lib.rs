//! brtf-radiance
