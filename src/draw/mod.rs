//! Drawing into an `RgbImage`: the one place the maps (`render`), the realism report
//! (`lab::eval`), the bench chart and the training previews get their bitmap text, lines,
//! rectangles and charts with axes from.
//!
//! Everything clips at the image's edges, so a label or a line that runs off the picture is
//! cut there instead of panicking.

pub mod chart;
mod shapes;
mod text;

pub use shapes::{fill, line, outline, put};
pub use text::{text, width, GLYPH};
