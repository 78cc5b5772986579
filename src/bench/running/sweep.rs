//! Parameter sweeps: `--size W H` (repeated), `--shadow-samples 16,64`, `--threads 1,2` give
//! the points of their Cartesian product, each benched and recorded on its own. A point is
//! named by the swept values only (`512x512+s64+t1`), and `--save NAME` saves it as
//! `NAME+LABEL.json`; a single point keeps the plain `NAME.json`.

/// The values each swept flag takes (empty: the flag was not given; one value: no sweep).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Sweep {
    /// Image sizes.
    pub sizes: Vec<[u32; 2]>,
    /// Points per light.
    pub shadow_samples: Vec<u32>,
    /// Worker threads.
    pub threads: Vec<u32>,
}

/// One point of a sweep: `None` where the flag was not given.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Point {
    /// Image size.
    pub size: Option<[u32; 2]>,
    /// Points per light.
    pub shadow_samples: Option<u32>,
    /// Worker threads.
    pub threads: Option<u32>,
    /// The swept values, `512x512+s64+t1`; empty for a single point.
    pub label: String,
}

/// `values` as options, `[None]` when empty.
fn each<T: Copy>(values: &[T]) -> Vec<Option<T>> {
    if values.is_empty() {
        vec![None]
    } else {
        values.iter().copied().map(Some).collect()
    }
}

impl Sweep {
    /// The points, sizes outermost, threads innermost.
    pub fn points(&self) -> Vec<Point> {
        let mut out = Vec::new();
        for size in each(&self.sizes) {
            for shadow_samples in each(&self.shadow_samples) {
                for threads in each(&self.threads) {
                    let mut parts = Vec::new();
                    if let (Some([w, h]), true) = (size, self.sizes.len() > 1) {
                        parts.push(format!("{w}x{h}"));
                    }
                    if let (Some(n), true) = (shadow_samples, self.shadow_samples.len() > 1) {
                        parts.push(format!("s{n}"));
                    }
                    if let (Some(t), true) = (threads, self.threads.len() > 1) {
                        parts.push(format!("t{t}"));
                    }
                    out.push(Point {
                        size,
                        shadow_samples,
                        threads,
                        label: parts.join("+"),
                    });
                }
            }
        }
        out
    }
}

/// The record name of the point labelled `label` under `--save NAME`: `NAME`, or `NAME+LABEL`
/// in a sweep.
pub fn record_name(name: &str, label: &str) -> String {
    if label.is_empty() {
        name.to_string()
    } else {
        format!("{name}+{label}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_are_the_product_and_labels_name_swept_values_only() {
        let sweep = Sweep {
            sizes: vec![[256, 256], [512, 384]],
            shadow_samples: vec![16],
            threads: vec![1, 2],
        };
        let labels: Vec<String> = sweep.points().into_iter().map(|p| p.label).collect();
        assert_eq!(
            labels,
            ["256x256+t1", "256x256+t2", "512x384+t1", "512x384+t2"]
        );
        assert_eq!(sweep.points()[3].shadow_samples, Some(16));
        let one = Sweep::default().points();
        assert_eq!(one.len(), 1);
        assert_eq!(record_name("base", &one[0].label), "base");
        assert_eq!(
            record_name("base", &sweep.points()[1].label),
            "base+256x256+t2"
        );
    }
}
