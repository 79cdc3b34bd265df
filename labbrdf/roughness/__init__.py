"""Surface roughness beyond the microfacet distributions: height maps, form, smoothness."""
