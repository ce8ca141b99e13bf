//! Test support: analytic derivatives against central finite differences.

/// Asserts that `grad(i)` and `hess(i, j)` match central differences of `energy` about the
/// origin of its N coordinates (relative to the largest analytic entry).
pub fn check_derivatives<const N: usize>(
    energy: impl Fn(&[f64; N]) -> f64,
    grad: impl Fn(usize) -> f64,
    hess: impl Fn(usize, usize) -> f64,
) {
    let at = |steps: &[(usize, f64)]| {
        let mut z = [0.0; N];
        for &(i, h) in steps {
            z[i] += h;
        }
        energy(&z)
    };
    let h = 1e-6;
    let scale = (0..N).map(|i| grad(i).abs()).fold(0.0, f64::max);
    for i in 0..N {
        let fd = (at(&[(i, h)]) - at(&[(i, -h)])) / (2.0 * h);
        let an = grad(i);
        assert!(
            (fd - an).abs() < 1e-6 * scale,
            "grad {i}: fd {fd} analytic {an}"
        );
    }
    let h = 1e-4;
    let scale = (0..N * N)
        .map(|k| hess(k / N, k % N).abs())
        .fold(0.0, f64::max);
    for i in 0..N {
        for j in 0..N {
            let fd = (at(&[(i, h), (j, h)]) - at(&[(i, h), (j, -h)]) - at(&[(i, -h), (j, h)])
                + at(&[(i, -h), (j, -h)]))
                / (4.0 * h * h);
            let an = hess(i, j);
            assert!(
                (fd - an).abs() < 1e-5 * scale,
                "hess {i},{j}: fd {fd} analytic {an}"
            );
        }
    }
}
