//! The Pareto front of points that cost something and err by something: a point is on the
//! front when no other point is at most as costly and at most as wrong, and strictly better in
//! one of the two.

/// Indices of the points on the front of `(cost, error)` pairs (both minimized), sorted by
/// cost. Points with a NaN coordinate are never on the front.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<usize> {
    let dominated = |i: usize| {
        let (c, e) = points[i];
        points
            .iter()
            .enumerate()
            .any(|(j, &(c2, e2))| j != i && c2 <= c && e2 <= e && (c2 < c || e2 < e))
    };
    let mut front: Vec<usize> = (0..points.len())
        .filter(|&i| !points[i].0.is_nan() && !points[i].1.is_nan() && !dominated(i))
        .collect();
    front.sort_by(|&a, &b| points[a].0.total_cmp(&points[b].0));
    front
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dominated_points_are_left_out_and_the_front_is_sorted_by_cost() {
        let pts = [
            (10.0, 1.0), // 0: cheap, bad
            (30.0, 0.1), // 1: front
            (40.0, 0.2), // 2: dominated by 1
            (20.0, 0.5), // 3: front
            (50.0, 0.0), // 4: front
            (20.0, 0.6), // 5: dominated by 3 (same cost, worse)
            (f64::NAN, 0.0),
        ];
        assert_eq!(pareto_front(&pts), vec![0, 3, 1, 4]);
    }

    #[test]
    fn equal_points_both_stay() {
        assert_eq!(pareto_front(&[(1.0, 1.0), (1.0, 1.0)]), vec![0, 1]);
    }
}
