//! The page: one HTML file with the viewer's script and every model inlined (base64 `.glb`
//! bytes in a JSON block), so it opens from disk with no network. `</` is escaped inside the
//! script blocks so no name can end them early.
//!
//! Cost: linear in the models' size (base64 adds a third).

use std::path::{Path, PathBuf};

use base64::Engine;
use serde_json::json;
use voxlod_io::{IoError, IoErrorKind};

use crate::check::{check_glb, CheckedGlb};
use crate::ViewError;

/// The renderer, embedded at build time.
const VIEWER_JS: &str = include_str!("viewer.js");

/// How the page looks.
#[derive(Clone, Debug, PartialEq)]
pub struct ViewOptions {
    /// The page's title until the viewer replaces it with what it draws.
    pub title: String,
}

impl Default for ViewOptions {
    fn default() -> Self {
        ViewOptions {
            title: "voxlod view".into(),
        }
    }
}

/// One model of the page.
#[derive(Clone, Debug)]
pub struct PageModel {
    pub name: String,
    pub glb: CheckedGlb,
}

/// Reads and checks a `.glb` (any from `lod`, `layers`, or another tool) for the page. A file
/// that cannot be read is an [`IoErrorKind::Access`] error, one that is not a usable `.glb` an
/// [`IoErrorKind::Malformed`] one, both naming the file.
pub fn read_model(path: &Path) -> Result<PageModel, ViewError> {
    let unreadable =
        |e: std::io::Error| IoError::new(path, IoErrorKind::Access, format!("cannot read: {e}"));
    let len = std::fs::metadata(path).map_err(unreadable)?.len();
    voxlod_core::memory::check_allocation(&format!("reading {}", path.display()), len)?;
    let bytes = std::fs::read(path).map_err(unreadable)?;
    let glb =
        check_glb(&bytes).map_err(|reason| IoError::new(path, IoErrorKind::Malformed, reason))?;
    let name = path.file_name().map_or_else(
        || path.display().to_string(),
        |n| n.to_string_lossy().into_owned(),
    );
    Ok(PageModel { name, glb })
}

/// The HTML of a page showing `models` (the first one first; keys 1–9 switch).
pub fn page_html(models: &[PageModel], options: &ViewOptions) -> Result<String, ViewError> {
    if models.is_empty() {
        return Err(ViewError::NoInput);
    }
    let encoder = base64::engine::general_purpose::STANDARD;
    let entries: Vec<_> = models
        .iter()
        .map(|m| json!({"name": m.name, "glb": encoder.encode(&m.glb.bytes)}))
        .collect();
    let data = serde_json::Value::Array(entries)
        .to_string()
        .replace("</", "<\\/");
    let title = escape_html(&options.title);
    let script = VIEWER_JS.replace("</", "<\\/");
    Ok(format!(
        "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">\
         <meta name=\"viewport\" content=\"width=device-width,initial-scale=1\">\
         <title>{title}</title>\n<style>html,body{{margin:0;height:100%;overflow:hidden;\
         background:#fff}}#view{{width:100%;height:100%;display:block;touch-action:none}}\
         #overlay{{position:fixed;left:32px;top:4px;font:13px/1.3 sans-serif;color:#222;\
         background:rgba(255,255,255,.8);padding:2px 6px;pointer-events:none}}</style></head>\n\
         <body><canvas id=\"view\"></canvas><div id=\"overlay\"></div>\n\
         <script type=\"application/json\" id=\"voxlod-data\">{data}</script>\n\
         <script>{script}</script>\n</body></html>\n"
    ))
}

/// Writes the page for the files `inputs` to `output`, atomically.
pub fn write_page(
    inputs: &[PathBuf],
    output: &Path,
    options: &ViewOptions,
) -> Result<Vec<PageModel>, ViewError> {
    let models = inputs
        .iter()
        .map(|p| read_model(p))
        .collect::<Result<Vec<_>, _>>()?;
    let html = page_html(&models, options)?;
    voxlod_io::atomic::write_atomically(output, |w| std::io::Write::write_all(w, html.as_bytes()))?;
    Ok(models)
}

fn escape_html(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
