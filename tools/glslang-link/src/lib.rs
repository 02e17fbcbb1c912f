//! Carries link directives only; see build.rs.
