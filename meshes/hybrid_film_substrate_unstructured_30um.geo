// hybrid_film_substrate_unstructured.geo with the bottom at y = -25 um: the far field of a 30 um
// substrate (studies/hybrid, runs to 6.4 ns), and a slower growth, 0.025 (cells 0.1 um at the
// band, about 0.8 um at the bottom; 5 615 nodes). Over 6.4 ns the probes see what the coarsening
// reflects from deeper down: with the 15 um run's growth of 0.1 (2 349 nodes) the film probes
// drift to 2.9-4.6 % from the all-MPM 30 um run, with 0.025 they stay within 1.2-1.8 %. (A
// growth of 0.05 leaves triangles that gmsh 4.8's Blossom recombination does not pair.)
// Same groups and parameters.
DefineConstant[ h = {5e-7, Name "Parameters/h"} ];
y0 = -25e-6;
grow = 0.025;
Include "hybrid_film_substrate_unstructured.geo";
