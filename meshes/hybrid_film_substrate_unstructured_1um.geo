// hybrid_film_substrate_unstructured.geo with the interface at y = 4 um: 1 um of silicon
// particles under the film (studies/hybrid). Same groups and parameters.
DefineConstant[ h = {5e-7, Name "Parameters/h"} ];
top = 4e-6;
Include "hybrid_film_substrate_unstructured.geo";
