"""Surface roughness beyond microfacets: height-map statistics, power spectra and their models."""
