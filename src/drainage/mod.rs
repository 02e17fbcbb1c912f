//! Drainage networks (beyond the thesis; docs/rivers.md): water routed over the whole sphere at the base
//! resolution, so rivers run downhill, join at confluences and end in the sea or in lakes. The thesis's rivers
//! (one random walk per mountain, Chapter 5) stay selectable as `<river-model>thesis</river-model>`.

pub mod grid;
pub mod rivers;
pub mod routing;
