"""Surface roughness beyond the microfacet distributions: height-map statistics, smoothness,
synthetic surfaces, power spectra and their models, Rayleigh-Rice scatter."""
