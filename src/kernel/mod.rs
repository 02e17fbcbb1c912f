//! The river-height kernel of Sections 6.5-6.6 and Chapter 7.
