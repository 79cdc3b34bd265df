"""Surface roughness beyond the microfacet distributions: spectra and perturbation scatter."""
