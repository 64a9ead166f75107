//! `[[fields]]`: an instance generator that lays many instances out on a grid in the XZ plane —
//! the paper's SunCOR idea of thousands of rigidly moving instances of a few objects.
//!
//! ```toml
//! [[fields]]
//! name = "crowd"                # optional, default "field<k>"; instances are "crowd[ix,iz]"
//! objects = ["ball", "cube"]    # or object = "ball"; each instance picks one at random
//! count_x = 40                  # grid columns (x) ...
//! count_z = 30                  # ... and rows (z); count_x * count_z <= 1,000,000
//! spacing = 1.5                 # distance between grid points, > 0
//! origin = [0.0, 0.0, 0.0]      # centre of the grid
//! jitter = 0.3                  # in [0, 1): each instance moves by up to ±jitter·spacing/2 in x and z
//! seed = 1                      # drives object choice, jitter and yaw (ChaCha8)
//! rotate = [0.0, 0.0, 0.0]      # base rotation, degrees X, Y, Z
//! random_yaw = true             # add a random turn in [0, 360) about Y
//! scale = [1.0, 1.0, 1.0]
//! animate = { frames = 8, translate_by = [0.0, 1.0, 0.0], rotate_by = [0.0, 90.0, 0.0] }
//! ```
//! Instances come row by row (z outer, x inner). For each one the generator draws, in this
//! order: object choice, x jitter, z jitter, yaw — always all four, so changing one option does
//! not reshuffle the others. A field's animation is relative: each instance ends at its own
//! start plus `translate_by` / `rotate_by` (scale stays).

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

use super::transform::{Animation, Instance, Transform};

/// Most instances a scene may place: what the processor's instance bank holds
/// (`MemoryConfig::max_instances`, 43,690 on the board). Fields are counted before they are
/// expanded, so a field of a million instances costs nothing but its message.
pub fn max_scene_instances() -> u64 {
    crate::layout::MemoryConfig::default().max_instances() as u64
}

/// A field with object names resolved and values validated.
#[derive(Debug, Clone)]
pub struct FieldSpec {
    pub name: String,
    pub objects: Vec<usize>,
    pub count_x: u32,
    pub count_z: u32,
    pub spacing: f64,
    pub origin: DVec3,
    pub jitter: f64,
    pub seed: u64,
    pub rotate_deg: DVec3,
    pub random_yaw: bool,
    pub scale: DVec3,
    /// (frames, translate_by, rotate_by)
    pub animate: Option<(u32, DVec3, DVec3)>,
}

/// The grid position of cell (ix, iz) before jitter.
pub fn grid_point(spec: &FieldSpec, ix: u32, iz: u32) -> DVec3 {
    let cx = (f64::from(ix) - f64::from(spec.count_x - 1) * 0.5) * spec.spacing;
    let cz = (f64::from(iz) - f64::from(spec.count_z - 1) * 0.5) * spec.spacing;
    spec.origin + DVec3::new(cx, 0.0, cz)
}

pub fn expand(spec: &FieldSpec) -> Vec<Instance> {
    let mut rng = ChaCha8Rng::seed_from_u64(spec.seed);
    let mut out = Vec::with_capacity(spec.count_x as usize * spec.count_z as usize);
    for iz in 0..spec.count_z {
        for ix in 0..spec.count_x {
            let pick = rng.gen_range(0..spec.objects.len());
            let jx: f64 = rng.gen::<f64>() - 0.5;
            let jz: f64 = rng.gen::<f64>() - 0.5;
            let yaw: f64 = rng.gen::<f64>() * 360.0;
            let offset = DVec3::new(jx, 0.0, jz) * (spec.jitter * spec.spacing);
            let mut rotate_deg = spec.rotate_deg;
            if spec.random_yaw {
                rotate_deg.y += yaw;
            }
            let transform = Transform {
                translate: grid_point(spec, ix, iz) + offset,
                rotate_deg,
                scale: spec.scale,
            };
            let animation = spec.animate.map(|(frames, by_t, by_r)| Animation {
                frames,
                end: Transform {
                    translate: transform.translate + by_t,
                    rotate_deg: transform.rotate_deg + by_r,
                    scale: transform.scale,
                },
            });
            out.push(Instance {
                object: spec.objects[pick],
                name: format!("{}[{ix},{iz}]", spec.name),
                transform,
                animation,
            });
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> FieldSpec {
        FieldSpec {
            name: "f".into(),
            objects: vec![3, 5, 7],
            count_x: 20,
            count_z: 10,
            spacing: 2.0,
            origin: DVec3::new(1.0, 0.5, -3.0),
            jitter: 0.4,
            seed: 11,
            rotate_deg: DVec3::new(10.0, 0.0, 0.0),
            random_yaw: true,
            scale: DVec3::splat(0.5),
            animate: Some((6, DVec3::new(0.0, 2.0, 0.0), DVec3::new(0.0, 90.0, 0.0))),
        }
    }

    #[test]
    fn grid_layout_jitter_and_choice() {
        let s = spec();
        println!("field seed {}", s.seed);
        let inst = expand(&s);
        assert_eq!(inst.len(), 200);
        assert_eq!(inst[0].name, "f[0,0]");
        assert_eq!(inst[21].name, "f[1,1]");
        for (k, i) in inst.iter().enumerate() {
            let (ix, iz) = ((k % 20) as u32, (k / 20) as u32);
            let d = i.transform.translate - grid_point(&s, ix, iz);
            assert!(d.x.abs() <= 0.4 && d.z.abs() <= 0.4 && d.y == 0.0, "{d}");
            assert!(s.objects.contains(&i.object));
            assert_eq!(i.transform.rotate_deg.x, 10.0);
            assert!((0.0..360.0).contains(&i.transform.rotate_deg.y));
            let a = i.animation.unwrap();
            assert_eq!(a.frames, 6);
            assert_eq!(
                a.end.translate,
                i.transform.translate + DVec3::new(0.0, 2.0, 0.0)
            );
            assert_eq!(a.end.rotate_deg.y, i.transform.rotate_deg.y + 90.0);
        }
        // Grid is centred on origin: first and last points are symmetric about it.
        let first = grid_point(&s, 0, 0);
        let last = grid_point(&s, 19, 9);
        assert_eq!((first + last) * 0.5, s.origin);
        assert_eq!(last.x - first.x, 38.0);
        // All three objects are used, roughly evenly.
        for o in &s.objects {
            let n = inst.iter().filter(|i| i.object == *o).count();
            assert!(n > 40, "object {o}: {n}");
        }
        // Jitter really varies, and the same seed reproduces the field.
        let dx: Vec<f64> = inst
            .iter()
            .enumerate()
            .map(|(k, i)| i.transform.translate.x - grid_point(&s, k as u32 % 20, k as u32 / 20).x)
            .collect();
        assert!(dx.iter().any(|&d| d > 0.2) && dx.iter().any(|&d| d < -0.2));
        assert_eq!(expand(&s), inst);
        let mut s2 = s.clone();
        s2.seed = 12;
        assert_ne!(expand(&s2), inst);
    }
}
