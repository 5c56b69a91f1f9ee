//! Adaptive Simpson quadrature: the independent numerical integration the closed forms and
//! the real-time discretisations are tested against.

/// Adaptive Simpson quadrature, written out so the analytic term is checked against an
/// independent numerical evaluation of the integral it claims to solve.
pub(crate) fn simpson(f: &dyn Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> f64 {
    /// One panel [a, b] with f at a, the midpoint and b, and its Simpson estimate `whole`.
    fn rec(
        f: &dyn Fn(f64) -> f64,
        (a, b): (f64, f64),
        (fa, fm, fb): (f64, f64, f64),
        whole: f64,
        tol: f64,
        depth: u32,
    ) -> f64 {
        let m = 0.5 * (a + b);
        let (flm, frm) = (f(0.5 * (a + m)), f(0.5 * (m + b)));
        let left = (m - a) / 6.0 * (fa + 4.0 * flm + fm);
        let right = (b - m) / 6.0 * (fm + 4.0 * frm + fb);
        if depth == 0 || (left + right - whole).abs() <= 15.0 * tol {
            return left + right + (left + right - whole) / 15.0;
        }
        rec(f, (a, m), (fa, flm, fm), left, tol / 2.0, depth - 1)
            + rec(f, (m, b), (fm, frm, fb), right, tol / 2.0, depth - 1)
    }
    let (fa, fb, fm) = (f(a), f(b), f(0.5 * (a + b)));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    rec(f, (a, b), (fa, fm, fb), whole, tol, 50)
}
