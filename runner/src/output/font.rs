//! The bundled TTF font (DejaVu Sans, `assets/fonts/`), registered with plotters' `ab_glyph` text
//! backend as its `sans-serif` family, so text renders the same on every machine with no system
//! fonts.

use std::sync::OnceLock;

static FONT: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// Registers the bundled font once; later calls return the first outcome. `false` if the font
/// could not be parsed (text is then not drawn).
pub(crate) fn register() -> bool {
    static REGISTERED: OnceLock<bool> = OnceLock::new();
    *REGISTERED.get_or_init(|| {
        plotters::style::register_font("sans-serif", plotters::style::FontStyle::Normal, FONT)
            .is_ok()
    })
}
