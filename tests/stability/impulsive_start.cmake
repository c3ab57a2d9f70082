# Impulsive start: the flexible-bottom cavity (12 x 12, 3 s) with the lid and the inflow at full
# speed from t = 0 (no 1 - cos ramp): the implicit coupling stays stable with and without the load
# filter (pNetFilterTau), the explicit scheme diverges.
include(${CMAKE_CURRENT_LIST_DIR}/lib/Checks.cmake)
file(REMOVE_RECURSE ${WORK})
set(cavity flexible-cavity --set mesh.blocks.0.cells=[12,10,1] --set mesh.blocks.1.cells=[12,2,1] --set time.endTime=3
  --set fluid.boundary.lid.timeFunction.type=constant --set fluid.boundary.inlet.timeFunction.type=constant)
stable(impulsive 30 10 ${cavity})
stable(impulsive_filtered 30 10 ${cavity} --set coupling.pNetFilterTau=0.2)
diverges(impulsive_explicit 30 ${cavity} --set coupling.scheme=explicit)
