//! `report.html`: the header, each stage's table and its plot (the SVG inline), in one file that
//! needs nothing beside it.

use std::fmt::Write;

use crate::plot::PlotFile;
use crate::{Report, markdown};

/// Escapes text for HTML.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A Markdown table (as `markdown::render` writes them) as an HTML table.
fn table_html(lines: &[&str]) -> String {
    let mut s = String::from("<table>\n");
    for (i, line) in lines.iter().enumerate() {
        if i == 1 {
            continue; // the |---| rule
        }
        let tag = if i == 0 { "th" } else { "td" };
        s += "<tr>";
        for cell in line.trim().trim_matches('|').split('|') {
            let _ = write!(s, "<{tag}>{}</{tag}>", escape(cell.trim()));
        }
        s += "</tr>\n";
    }
    s + "</table>\n"
}

pub fn render(report: &Report, plots: &[PlotFile]) -> String {
    page(
        "Slipgate: speed against error",
        &markdown::header(report),
        &markdown::render(report, plots),
        plots,
    )
}

/// A self-contained page: the title, the header paragraph, then the Markdown from its first
/// `## ` heading on, with each plot's image link replaced by its inline SVG.
pub fn page(title: &str, header: &str, markdown: &str, plots: &[PlotFile]) -> String {
    let mut s = format!(
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\"/>\n\
         <title>{title}</title>\n<style>\n\
         body {{ font-family: sans-serif; margin: 2em; max-width: 80em; }}\n\
         table {{ border-collapse: collapse; margin: 1em 0; }}\n\
         th, td {{ border: 1px solid #bbb; padding: 0.2em 0.6em; text-align: right; }}\n\
         th {{ background: #eee; }}\n\
         td:nth-child(-n+3) {{ text-align: left; }}\n\
         </style>\n</head>\n<body>\n<h1>{title}</h1>\n",
        title = escape(title)
    );
    let _ = writeln!(s, "<p>{}</p>", escape(header));
    // Walk the Markdown: headings, paragraphs and tables become HTML; each stage's image link
    // becomes its inline SVG.
    let lines: Vec<&str> = markdown.lines().collect();
    let mut i = lines
        .iter()
        .position(|l| l.starts_with("## "))
        .unwrap_or(lines.len());
    while i < lines.len() {
        let line = lines[i];
        if let Some(title) = line.strip_prefix("## ") {
            let _ = writeln!(s, "<h2>{}</h2>", escape(title));
        } else if line.starts_with('|') {
            let end = lines[i..]
                .iter()
                .position(|l| !l.starts_with('|'))
                .map_or(lines.len(), |n| i + n);
            s += &table_html(&lines[i..end]);
            i = end;
            continue;
        } else if line.starts_with("![") {
            let plot = plots
                .iter()
                .find(|p| line.contains(&format!("({})", p.png)));
            if let Some(p) = plot {
                s += "<figure>";
                s += strip_xml_declaration(&p.svg_text);
                s += "</figure>\n";
            }
        } else if let Some(item) = line.strip_prefix("- ") {
            let _ = writeln!(s, "<p>{}</p>", escape(item));
        } else if !line.trim().is_empty() {
            let _ = writeln!(s, "<p>{}</p>", escape(line));
        }
        i += 1;
    }
    s + "</body>\n</html>\n"
}

/// An SVG document without its `<?xml ...?>` line, to sit inside HTML.
fn strip_xml_declaration(svg: &str) -> &str {
    match svg.find("<svg") {
        Some(at) => &svg[at..],
        None => svg,
    }
}
