//! Detection scores (SPEC §6).
