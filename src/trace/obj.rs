//! The scene and the tree as a Wavefront OBJ: one `o` object per group (`mesh.rs`), vertices
//! with colours (`v x y z r g b`, the extension Blender and MeshLab read), triangles as `f`
//! and rays as `l` line elements. Indices are 1-based and global, as OBJ wants.

use super::mesh::Group;
use std::io::Write;

/// Writes the groups as OBJ; `title` goes in the header comment.
pub fn write_obj(out: &mut dyn Write, title: &str, groups: &[Group]) -> std::io::Result<()> {
    writeln!(out, "# {title}")?;
    writeln!(
        out,
        "# written by raywave {}: one object per group; rays are `l` lines",
        env!("CARGO_PKG_VERSION")
    )?;
    let mut base = 1u32;
    for g in groups {
        writeln!(out, "o {}", g.name)?;
        for (p, c) in &g.vertices {
            writeln!(
                out,
                "v {} {} {} {:.4} {:.4} {:.4}",
                p.x,
                p.y,
                p.z,
                f32::from(c[0]) / 255.0,
                f32::from(c[1]) / 255.0,
                f32::from(c[2]) / 255.0
            )?;
        }
        for [a, b, c] in &g.triangles {
            writeln!(out, "f {} {} {}", a + base, b + base, c + base)?;
        }
        for [a, b] in &g.lines {
            writeln!(out, "l {} {}", a + base, b + base)?;
        }
        base += g.vertices.len() as u32;
    }
    Ok(())
}
