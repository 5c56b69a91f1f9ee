#!/usr/bin/env python3
"""Diffuse-sky to direct-sun irradiance ratio just below a flat sea surface, for `water.sky`.

Oracle script (not a runtime dependency): the clear-sky spectral model SPCTRAL2 (Bird &
Riordan 1986, J. Climate Appl. Meteor. 25, 87-97, as implemented by pvlib's
`pvlib.spectrum.spectrl2`) gives the direct-beam and the diffuse (sky) spectral irradiance on
a horizontal plane above the sea. Both are weighted with the CIE 1931 ybar (colour-science) to
luminance-like totals; below the surface the sun keeps the Fresnel transmittance T(theta_sun)
and a uniform sky keeps the hemispherical mean Tbar (n = 1.34, as scene::water and truth use):

    sky = (E_sky_above * Tbar) / (E_sun_above * T(theta_sun))

Also prints the irradiance a vertical face receives from that sky just below the surface, as a
fraction of a horizontal face's (what the real-time zenith stand-in light gets wrong).

Usage: python3 tools/sky_ratio.py [ZENITH_DEG ...]     (needs: pip install pvlib colour-science)
"""
import sys

import colour
import numpy as np
import pvlib

N_WATER = 1.34


def fresnel_t(mu_air, n=N_WATER):
    """Unpolarised Fresnel transmittance air -> water for the cosine mu_air of incidence."""
    st = np.sqrt(1.0 - mu_air * mu_air) / n
    ct = np.sqrt(1.0 - st * st)
    rs = ((mu_air - n * ct) / (mu_air + n * ct)) ** 2
    rp = ((ct - n * mu_air) / (ct + n * mu_air)) ** 2
    return 1.0 - 0.5 * (rs + rp)


def mean_t(n=N_WATER, k=200_000):
    mu = (np.arange(k) + 0.5) / k
    return float(np.sum(fresnel_t(mu, n) * 2.0 * mu) / k)


def vertical_fraction(n=N_WATER, k=200_000):
    """Irradiance on a vertical face just below the surface from a uniform sky seen through
    Snell's window (radiance L_air*T*n^2 inside it), as a fraction of that on a horizontal face."""
    th = (np.arange(k) + 0.5) / k * (np.pi / 2)
    cw = np.cos(th)
    sin_a = np.minimum(n * np.sin(th), 1.0)
    t = np.where(n * np.sin(th) < 1.0, fresnel_t(np.sqrt(1.0 - sin_a * sin_a), n), 0.0)
    dth = np.pi / 2 / k
    e_h = 2 * np.pi * np.sum(t * cw * np.sin(th)) * dth
    e_v = 2 * np.sum(t * np.sin(th) ** 2) * dth
    return e_v / e_h


def ratio(zenith_deg, aerosol=0.1, water=1.4, alpha=1.14):
    z = np.array([zenith_deg])
    am = pvlib.atmosphere.get_relative_airmass(z, model="kasten1966")
    sp = pvlib.spectrum.spectrl2(
        apparent_zenith=z, aoi=z, surface_tilt=0.0, ground_albedo=0.06, surface_pressure=101325.0,
        relative_airmass=am, precipitable_water=water, ozone=0.31, aerosol_turbidity_500nm=aerosol,
        dayofyear=172, alpha=alpha,
    )
    wl = sp["wavelength"]
    keep = (wl >= 360) & (wl <= 830)
    wl = wl[keep]
    ybar = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(
        colour.SpectralShape(360, 830, 1)
    )
    y = np.interp(wl, ybar.wavelengths, ybar.values[:, 1])
    direct_h = sp["poa_direct"][keep, 0]  # beam on the horizontal plane (aoi = zenith)
    diffuse_h = sp["poa_sky_diffuse"][keep, 0]
    e_sun = np.trapezoid(direct_h * y, wl)
    e_sky = np.trapezoid(diffuse_h * y, wl)
    above = e_sky / e_sun
    below = above * mean_t() / fresnel_t(np.cos(np.radians(zenith_deg)))
    return above, below


def main():
    zs = [float(a) for a in sys.argv[1:]] or [20.0, 34.06, 45.0, 60.0]
    print(f"Tbar(n={N_WATER}) = {mean_t():.6f}")
    print(f"vertical / horizontal irradiance below the surface (Snell's window) = {vertical_fraction():.4f}")
    print("zenith  aerosol(500nm)  sky/sun above  sky/sun below")
    for z in zs:
        for tau in (0.05, 0.1, 0.2):
            a, b = ratio(z, aerosol=tau)
            print(f"{z:6.1f}  {tau:14.2f}  {a:13.3f}  {b:13.3f}")


if __name__ == "__main__":
    main()
