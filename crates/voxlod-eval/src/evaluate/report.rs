//! The Markdown write-up of an evaluation: the input, the chart, a side-by-side table of the
//! methods at each budget, one detailed table per method, and what was left out. Pure string
//! building, linear in the number of levels.

use std::fmt::Write;

use super::error::parameter_text;
use super::plot::method_colour;
use super::results::{Curve, CurvePoint, Evaluation};
use crate::methods::Method;

/// What the report says besides the evaluation itself.
#[derive(Clone, Debug, Default)]
pub struct ReportContext {
    /// The input as the user named it.
    pub input: String,
    /// The chart's file name beside the report, if one was drawn.
    pub plot_file: Option<String>,
    /// The chart has no text (no font was found): the report then gives the colours.
    pub plot_unlabelled: bool,
    /// Preview strips beside the report, per method (file names).
    pub previews: Vec<(Method, String)>,
    /// Extra notes (written files, warnings).
    pub notes: Vec<String>,
}

fn percent(fraction: f64) -> String {
    let p = 100.0 * fraction;
    if p >= 10.0 {
        format!("{p:.1}")
    } else if p >= 1.0 {
        format!("{p:.2}")
    } else {
        format!("{p:.3}")
    }
}

fn genus(g: Option<i64>) -> String {
    g.map_or("–".into(), |g| g.to_string())
}

/// The report as Markdown.
pub fn markdown(evaluation: &Evaluation, context: &ReportContext) -> String {
    let mut out = String::new();
    let e = evaluation;
    let i = &e.input;
    let _ = writeln!(out, "# Evaluation of `{}`\n", context.input);
    let _ = writeln!(
        out,
        "The input has {} vertices and {} triangles (area {:.6e}, bounding-box diagonal {:.6e}); \
         after welding coincident vertices it has {} component(s), {} boundary loop(s), genus {}, \
         and it is {}a closed manifold. Drawn as given it takes {} draw call(s), one per \
         material its triangles use.\n",
        i.vertices,
        i.triangles,
        i.area,
        i.diagonal,
        i.components,
        i.boundary_loops,
        genus(i.genus),
        if i.closed_manifold { "" } else { "not " },
        i.draw_calls
    );
    let _ = writeln!(
        out,
        "Each method ran at the parameter whose output came nearest each triangle budget ({}), \
         accepting a level within {:.0} % of its budget. Errors are two-sided surface distances \
         to the input, sampled with {} points per surface, in percent of the input's diagonal. \
         Total time {:.1} s.\n",
        e.budgets
            .iter()
            .map(|b| b.to_string())
            .collect::<Vec<_>>()
            .join(", "),
        100.0 * e.tolerance,
        e.samples_per_side,
        e.seconds
    );
    if let Some(plot) = &context.plot_file {
        let _ = writeln!(out, "![error against triangle count]({plot})\n");
        if context.plot_unlabelled {
            let _ = writeln!(
                out,
                "The chart has no text (no TrueType font was found; set `VOXLOD_FONT`). Left: \
                 Hausdorff distance, right: mean distance, both against triangles, log–log. \
                 Colours:\n"
            );
            for c in &e.curves {
                let (r, g, b) = method_colour(c.method);
                let _ = writeln!(out, "- `#{r:02x}{g:02x}{b:02x}`: {}", c.method);
            }
            out.push('\n');
        }
    }

    side_by_side(&mut out, e);
    draw_call_table(&mut out, e);
    for curve in &e.curves {
        method_table(&mut out, curve);
        if let Some((_, file)) = context.previews.iter().find(|(m, _)| *m == curve.method) {
            let _ = writeln!(
                out,
                "![{} levels]({file})\n\nThe input, then the levels above from the most \
                 triangles to the fewest.\n",
                curve.method
            );
        }
    }

    how_to_read(&mut out, e);
    if !e.omitted.is_empty() || !context.notes.is_empty() {
        let _ = writeln!(out, "\n## Not evaluated, and notes\n");
        for o in &e.omitted {
            let _ = writeln!(out, "- {}: {}.", o.what, o.reason);
        }
        for n in &context.notes {
            let _ = writeln!(out, "- {n}");
        }
    }
    out
}

/// The section that says how each measure is made.
fn how_to_read(out: &mut String, e: &Evaluation) {
    let _ = writeln!(out, "## How to read this\n");
    let _ = writeln!(
        out,
        "- Hausdorff is the largest distance found between the two surfaces in either direction \
         (the larger of input→level, how far the input's samples are from the level, and \
         level→input); mean and RMS average over the samples of both surfaces. Sampling finds a \
         lower bound of the true Hausdorff distance.\n\
         - The voxel levels are closed manifolds by construction (marching cubes on a padded \
         grid); holes of the input are closed before sampling, so a level's surface includes \
         caps that the input does not have, and they count in its distance.\n\
         - Clustering leaves dangling edges and isolated points where triangles collapsed; they \
         are counted but have no area, so only the triangles are measured. Its output is \
         usually not a manifold (genus undefined: –).\n\
         - Two budgets whose nearest level is the same are reported once.\n\
         - Draw calls: one per material a level's triangles use as it is drawn. A \
         simplifier's level is one mesh, its looks (when the input has some) taken from the \
         input as vertex colours: one call. The proxy's level is one mesh with one baked \
         material: one call."
    );
    if e.curves.iter().any(|c| c.method == super::PROXY) {
        let _ = writeln!(
            out,
            "- The proxy (`voxlod proxy`) is made from the whole input with its looks, at each \
             budget at once: its parameter is the budget. Its appearance is drawn with its own \
             baked textures, where the other methods' levels take their looks from the \
             nearest input points."
        );
    }
    if e.image_views > 0 {
        let _ = writeln!(
            out,
            "- Silhouette difference: the input and each level rendered from {} views \
             ({} × {} pixels, orthographic, framing the input's box); the share of pixels \
             covered in one image but not the other, among those covered in either. Dangling \
             edges count one pixel wide.",
            e.image_views, e.image_size, e.image_size
        );
    }
}

/// One row per budget, one column per method: triangles and Hausdorff / mean distance.
fn side_by_side(out: &mut String, e: &Evaluation) {
    let _ = writeln!(
        out,
        "## At each budget\n\nTriangles, then Hausdorff / mean distance in % of the diagonal{}{}.\n",
        if e.image_views > 0 {
            " / silhouette difference in % of covered pixels"
        } else {
            ""
        },
        if e.appearance_views > 0 {
            ", then the appearance (looks taken from the input; the proxy's own baked \
             textures): PSNR in dB · SSIM over its views"
        } else {
            ""
        }
    );
    method_columns(out, e, ["| budget |", "|---:|"], "---|");
    for &budget in &e.budgets {
        let _ = write!(out, "| {budget} |");
        for c in &e.curves {
            match c.points.iter().find(|p| p.budget == budget) {
                Some(p) => {
                    let _ = write!(
                        out,
                        " {} · {} / {}{} |",
                        p.triangles,
                        percent(p.hausdorff_fraction),
                        percent(p.mean_fraction),
                        p.image_difference
                            .map_or(String::new(), |d| format!(" / {}", percent(d.fraction)))
                    );
                    if let Some(a) = p.appearance {
                        out.truncate(out.len() - 2); // the cell's closing " |"
                        let _ = write!(out, " ({:.1} dB · {:.3}) |", a.psnr, a.ssim);
                    }
                }
                None => out.push_str(" – |"),
            }
        }
        out.push('\n');
    }
    out.push('\n');
}

/// A table's header and rule: the `lead` cells and their rule, then a column per method, each
/// ruled `rule`.
fn method_columns(out: &mut String, e: &Evaluation, lead: [&str; 2], rule: &str) {
    out.push_str(lead[0]);
    for c in &e.curves {
        let _ = write!(out, " {} |", c.method);
    }
    out.push('\n');
    out.push_str(lead[1]);
    for _ in &e.curves {
        out.push_str(rule);
    }
    out.push('\n');
}

/// The input's draw calls beside each method's: one row, the range over a method's levels.
fn draw_call_table(out: &mut String, e: &Evaluation) {
    let _ = writeln!(
        out,
        "## Draw calls\n\nOne per material a mesh's triangles use as it is drawn.\n"
    );
    method_columns(out, e, ["| | input |", "|---|---:|"], "---:|");
    let _ = write!(out, "| draw calls | {} |", e.input.draw_calls);
    for c in &e.curves {
        let calls = c.points.iter().map(|p| p.draw_calls);
        match (calls.clone().min(), calls.max()) {
            (Some(a), Some(b)) if a == b => {
                let _ = write!(out, " {a} |");
            }
            (Some(a), Some(b)) => {
                let _ = write!(out, " {a}–{b} |");
            }
            _ => out.push_str(" – |"),
        }
    }
    out.push_str("\n\n");
}

fn method_table(out: &mut String, c: &Curve) {
    let _ = writeln!(
        out,
        "## {}\n\n{} runs in {:.2} s (searching and measuring).\n",
        c.method, c.trials, c.seconds
    );
    let _ = writeln!(
        out,
        "| budget | {} | triangles | vertices | Hausdorff % | input→level % | level→input % \
         | mean % | RMS % | silhouette % | components | genus | closed manifold \
         | dangling edges | points | draw calls | seconds |",
        c.parameter
    );
    let _ = writeln!(
        out,
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---|---:|---:|---:|---:|"
    );
    for p in &c.points {
        row(out, p);
    }
    for m in &c.misses {
        let _ = writeln!(out, "\n- {m}");
    }
    for n in &c.notes {
        let _ = writeln!(out, "\n- {n}");
    }
    out.push('\n');
}

fn row(out: &mut String, p: &CurvePoint) {
    let _ = writeln!(
        out,
        "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.3} |",
        p.budget,
        parameter_text(p.parameter),
        p.triangles,
        p.vertices,
        percent(p.hausdorff_fraction),
        percent(p.input_to_level_fraction),
        percent(p.level_to_input_fraction),
        percent(p.mean_fraction),
        percent(p.rms_fraction),
        p.image_difference
            .map_or("–".to_string(), |d| percent(d.fraction)),
        p.components,
        genus(p.genus),
        if p.closed_manifold { "yes" } else { "no" },
        p.dangling_edges,
        p.isolated_points,
        p.draw_calls,
        p.simplify_seconds
    );
}
