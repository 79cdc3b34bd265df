"""Surface roughness beyond the microfacet distributions: height maps, smoothness, synthetics."""
