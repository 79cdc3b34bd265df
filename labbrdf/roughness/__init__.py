"""Surface roughness beyond the microfacet distributions.

Height-map statistics, smoothness, synthetic surfaces, power spectra and their models,
Rayleigh-Rice scatter.
"""
