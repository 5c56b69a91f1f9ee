//! `KHR_materials_clearcoat` at a surface point, as the extension layers it
//! (`scene::clearcoat`): f = (1 − w)·f_base + w·f_coat, w = strength · F(|V·N_c|), and the
//! base's emission times 1 − w. The weight depends on the view direction only, so for one
//! `wo` the coat is a mixture of two BSDFs, the same at every wavelength; the integrator
//! samples it as one (coat with probability [`Coat::p`], the base otherwise) and evaluates
//! value and pdf as the same mixture, which keeps MIS with light sampling right.

use crate::bsdf::CoatLobe;
use crate::sampling::Frame;
use glam::Vec3;

/// A coat seen from one direction `wo` (world space).
#[derive(Clone, Copy, Debug)]
pub struct Coat {
    /// Around the coat's normal N_c, turned towards `wo`.
    pub frame: Frame,
    pub lobe: CoatLobe,
    /// w: the coat's share of the reflection at `wo`; 1 − w is the base's share of everything
    /// (reflection, transmission, emission).
    pub weight: f32,
    /// The probability of sampling the coat lobe rather than the base.
    pub p: f32,
}

impl Coat {
    /// The coat of `strength` and perceptual `roughness` about unit normal `n` (on the side
    /// of `wo`), seen from `wo`; sampled with probability w until [`Self::balanced`].
    pub fn new(strength: f32, roughness: f32, n: Vec3, wo: Vec3) -> Self {
        let weight = scene::clearcoat::layer_weight(strength, n.dot(wo));
        Coat { frame: Frame::from_normal(n), lobe: CoatLobe::new(roughness), weight, p: weight }
    }

    /// Samples the coat in proportion to the light each layer returns: w against (1 − w) times
    /// the base's estimated albedo `base_albedo`. A dark base under a coat (car paint) then
    /// draws about half its directions from the coat, whose sharp reflection light sampling
    /// cannot find, rather than the 4 % w gives at normal incidence. The base keeps at least
    /// 5 %, so no direction it reflects into goes unsampled.
    pub fn balanced(mut self, base_albedo: f32) -> Self {
        let w = self.weight;
        let denom = w + (1.0 - w) * base_albedo.max(0.0);
        self.p = if denom > 0.0 { (w / denom).min(0.95) } else { 0.95 };
        self
    }

    /// f_coat·cos θ_c (about the coat's normal) and the coat lobe's pdf, for world directions;
    /// zero where `wi` is below either the coat or the (flipped) geometric normal `ng`.
    pub fn eval(&self, ng: Vec3, wo: Vec3, wi: Vec3) -> (f32, f32) {
        if ng.dot(wi) <= 0.0 {
            return (0.0, 0.0);
        }
        let (lo, li) = (self.frame.to_local(wo), self.frame.to_local(wi));
        (self.lobe.eval(lo, li) * li.z.max(0.0), self.lobe.pdf(lo, li))
    }

    /// A world direction drawn from the coat lobe.
    pub fn sample(&self, wo: Vec3, u: [f32; 2]) -> Option<Vec3> {
        self.lobe.sample(self.frame.to_local(wo), u).map(|wi| self.frame.to_world(wi))
    }
}
