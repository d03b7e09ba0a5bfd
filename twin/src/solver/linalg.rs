//! Dense LU factorisation with partial pivoting for the small (≤ ~20) Newton/Rosenbrock
//! matrices of the integrator. Hand-written: the state is tiny and a linear-algebra crate would
//! dominate the build time (docs/model.md, "Integrator").

/// An LU factorisation of a square matrix stored row-major.
#[derive(Clone, Debug)]
pub struct Lu {
    n: usize,
    a: Vec<f64>,
    piv: Vec<usize>,
}

impl Lu {
    /// Factorise the `n × n` row-major matrix `a`; `None` if it is singular or not finite.
    pub fn factor(n: usize, mut a: Vec<f64>) -> Option<Lu> {
        if a.len() != n * n {
            return None;
        }
        let mut piv = vec![0; n];
        for k in 0..n {
            let mut p = k;
            let mut best = a.get(k * n + k).copied().unwrap_or(0.0).abs();
            for i in k + 1..n {
                let v = a.get(i * n + k).copied().unwrap_or(0.0).abs();
                if v > best {
                    best = v;
                    p = i;
                }
            }
            if !(best.is_finite() && best > 0.0) {
                return None;
            }
            if let Some(slot) = piv.get_mut(k) {
                *slot = p;
            }
            if p != k {
                for j in 0..n {
                    a.swap(k * n + j, p * n + j);
                }
            }
            let pivot = a.get(k * n + k).copied().unwrap_or(1.0);
            for i in k + 1..n {
                let factor = a.get(i * n + k).copied().unwrap_or(0.0) / pivot;
                if let Some(slot) = a.get_mut(i * n + k) {
                    *slot = factor;
                }
                if factor != 0.0 {
                    for j in k + 1..n {
                        let akj = a.get(k * n + j).copied().unwrap_or(0.0);
                        if let Some(slot) = a.get_mut(i * n + j) {
                            *slot -= factor * akj;
                        }
                    }
                }
            }
        }
        Some(Lu { n, a, piv })
    }

    /// Solve `A·x = b` in place.
    pub fn solve(&self, b: &mut [f64]) {
        let n = self.n;
        for k in 0..n {
            let p = self.piv.get(k).copied().unwrap_or(k);
            if p != k {
                b.swap(k, p);
            }
        }
        for i in 0..n {
            let mut s = b.get(i).copied().unwrap_or(0.0);
            for j in 0..i {
                s -= self.a.get(i * n + j).copied().unwrap_or(0.0)
                    * b.get(j).copied().unwrap_or(0.0);
            }
            if let Some(slot) = b.get_mut(i) {
                *slot = s;
            }
        }
        for i in (0..n).rev() {
            let mut s = b.get(i).copied().unwrap_or(0.0);
            for j in i + 1..n {
                s -= self.a.get(i * n + j).copied().unwrap_or(0.0)
                    * b.get(j).copied().unwrap_or(0.0);
            }
            if let Some(slot) = b.get_mut(i) {
                *slot = s / self.a.get(i * n + i).copied().unwrap_or(1.0);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system() {
        let a = vec![0.0, 2.0, 1.0, 1.0, 1.0, 0.0, 2.0, 0.0, 3.0];
        let lu = Lu::factor(3, a.clone()).unwrap();
        let x = [1.0, -2.0, 0.5];
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i * 3 + j] * x[j]).sum())
            .collect();
        lu.solve(&mut b);
        for i in 0..3 {
            assert!((b[i] - x[i]).abs() < 1e-12);
        }
        assert!(Lu::factor(2, vec![1.0, 2.0, 2.0, 4.0]).is_none());
    }
}
