//! Least-squares polynomial fits of the error over the measurement window.

/// Least-squares polynomial of degree `deg` (<= 2) through `(t, y)`, in powers of `t - t_c`
/// with `t_c` the mean time: solves the normal equations `(V^T V) c = V^T y`.
pub(super) fn polyfit(pts: &[(f64, f64)], deg: usize) -> (Vec<f64>, f64) {
    let n = deg + 1;
    let tc = pts.iter().map(|p| p.0).sum::<f64>() / pts.len() as f64;
    let mut a = vec![vec![0.0; n + 1]; n];
    for &(t, y) in pts {
        let x = t - tc;
        let pw: Vec<f64> = (0..n).map(|i| x.powi(i as i32)).collect();
        for i in 0..n {
            for j in 0..n {
                a[i][j] += pw[i] * pw[j];
            }
            a[i][n] += pw[i] * y;
        }
    }
    // Gauss-Jordan with partial pivoting.
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap_or(col);
        a.swap(col, piv);
        let d = a[col][col];
        for v in a[col].iter_mut() {
            *v /= d;
        }
        for r in 0..n {
            if r != col {
                let f = a[r][col];
                let row = a[col].clone();
                for (v, pv) in a[r].iter_mut().zip(&row) {
                    *v -= f * pv;
                }
            }
        }
    }
    ((0..n).map(|i| a[i][n]).collect(), tc)
}

pub(super) fn eval_fit(fit: &(Vec<f64>, f64), t: f64) -> f64 {
    let x = t - fit.1;
    fit.0.iter().rev().fold(0.0, |acc, c| acc * x + c)
}
