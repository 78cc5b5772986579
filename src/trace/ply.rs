//! The scene and the tree as an ASCII PLY: every group's vertices (with 8-bit colours), their
//! triangles as `face` elements and their rays as `edge` elements (vertex1, vertex2 and a
//! colour), the layout MeshLab and Blender read. PLY has no groups: the colours tell the rays
//! apart (palette.rs), and a comment line per group gives its vertex range.

use super::mesh::Group;
use std::io::Write;

/// Writes the groups as one PLY; `title` goes in a comment.
pub fn write_ply(out: &mut dyn Write, title: &str, groups: &[Group]) -> std::io::Result<()> {
    let vertices: usize = groups.iter().map(|g| g.vertices.len()).sum();
    let faces: usize = groups.iter().map(|g| g.triangles.len()).sum();
    let edges: usize = groups.iter().map(|g| g.lines.len()).sum();
    writeln!(out, "ply\nformat ascii 1.0")?;
    writeln!(out, "comment {title}")?;
    let mut base = 0usize;
    for g in groups {
        writeln!(
            out,
            "comment group {} vertices {}..{}",
            g.name,
            base,
            base + g.vertices.len()
        )?;
        base += g.vertices.len();
    }
    writeln!(out, "element vertex {vertices}")?;
    const COLOUR: &str = "property uchar red\nproperty uchar green\nproperty uchar blue";
    writeln!(
        out,
        "property float x\nproperty float y\nproperty float z\n{COLOUR}"
    )?;
    writeln!(out, "element face {faces}")?;
    writeln!(out, "property list uchar int vertex_indices")?;
    writeln!(out, "element edge {edges}")?;
    writeln!(out, "property int vertex1\nproperty int vertex2\n{COLOUR}")?;
    writeln!(out, "end_header")?;
    for g in groups {
        for (p, c) in &g.vertices {
            writeln!(out, "{} {} {} {} {} {}", p.x, p.y, p.z, c[0], c[1], c[2])?;
        }
    }
    let mut base = 0u32;
    for g in groups {
        for [a, b, c] in &g.triangles {
            writeln!(out, "3 {} {} {}", a + base, b + base, c + base)?;
        }
        base += g.vertices.len() as u32;
    }
    let mut base = 0u32;
    for g in groups {
        for [a, b] in &g.lines {
            let c = g.vertices[*a as usize].1;
            writeln!(out, "{} {} {} {} {}", a + base, b + base, c[0], c[1], c[2])?;
        }
        base += g.vertices.len() as u32;
    }
    Ok(())
}
