# `mpiexec -np N mfsi run` of FSI scenes: the same answer as one rank.
# - The flexible-bottom cavity (a membrane patch, IQN-ILS, CG mesh motion with sliding walls) at
#   12 x 12 for 1 s, solver and coupling tolerances tight: on 2 and 4 ranks the membrane's centre
#   displacement and stress, the largest speed, the moved mesh's volume and quality (each rank
#   measures its part, each face once) agree with one rank to
#   1e-10 relative, with the same coupling iterations; a second run on 2 ranks repeats the first
#   bit for bit (steps.csv without the wall time).
# - The piston (a rigid body, added mass 100 x its own): the force and acceleration on 2 ranks to
#   1e-9 (fsiTol 1e-13; the iteration count may differ by rank count at that level).
# - The membrane channel (two baffle membranes mounted on a sliding rigid frame): the bar's force
#   on 2 ranks to 1e-9; the frame's, which carries the panels' inertia relative to it (their
#   accelerations: the displacement's differences times 4 / dt^2), to 1e-8 (measured 1.4e-9); the
#   panel's centre displacement (1e-9 m) to 1e-7.
# - The balloon (a closed chamber: a membrane with a volume constraint) to t = 2 s: on 2 ranks the
#   membrane's centre displacement to 1e-8, the chamber's volume to 1e-10 and its pressure (the
#   multiplier plus the fluid's mean load) to 1e-6 of one rank's (measured 1.4e-10, 2e-13, 5e-8).
# - Mesh motion by columns (the cavity's, from the membrane to the lid): the same columns and
#   answer on 2 and 4 ranks to 1e-10; the VAD pump with both chambers meshed (columns on both
#   sides of the membrane, the air a closed chamber) for 5 ms on 2 ranks as on one.
# - One region bounded by two membranes (their shared multiplier), each solved by its own rank:
#   the same as one rank's (deflections 1e-8, volume 1e-10, pressure 2e-6).
# - A chamber under a sprung lid that carries its membrane: the same as one rank's (the lid's rise
#   and the deflection 1e-8, the volume 1e-10, the pressure 1e-7); a lumped gas chamber riding in
#   the lid likewise; a membrane blended between two sprung lids likewise.
# - A membrane between two closed regions, each membrane on its own rank: the same as one rank's
#   (deflections 1e-8, volumes 1e-10, pressures 1e-6).
# - Two screens far apart: each solved by its own rank only (one per rank), the answer sent to
#   the other: the same as one rank's to 1e-9.
# - `mfsi partition` writes the map a run computes: the cavity run on 2 ranks with --partition
#   repeats the METIS run bit for bit; a map with a bad line is refused naming file and line, a
#   map that splits the membrane's cells over two ranks naming the membrane.
# - Checkpoints on 2 ranks (one file per rank, the oldest pruned on every rank): a restart on 2
#   ranks from the middle of the cavity run gives the same steps bit for bit; a restart on 3 ranks
#   and on one (the state carried to another decomposition) ends where the uninterrupted run
#   does, to 1e-9, as does one rank's checkpoint continued on 2 ranks.
# With SHORT (the instrumented builds) the 4-rank cavities and the 3-rank restart are left out (the
# restarts on 1 and 2 ranks carry a state to another decomposition as well), the channel runs on
# half the cells along the flow, the balloon stops at t = 0.5 s and the VAD at 1 ms, and the
# nested chambers and the two lids are left out.
find_program(MPIEXEC mpiexec)
if(NOT MPIEXEC)
  message("MFSI_SKIP: no mpiexec")
  return()
endif()
file(REMOVE_RECURSE ${WORK})
set(tight --set coupling.fsiTol=1e-9 --set fluid.solvers.pressure.relTol=0 --set fluid.solvers.pressure.finalRelTol=0
  --set fluid.solvers.pressure.tolerance=1e-13 --set fluid.solvers.momentum.relTol=0
  --set fluid.solvers.momentum.tolerance=1e-13 --set coupling.meshMotion.relTol=1e-12
  --set fluid.pimple.outerTolerance=0)

# run(<name> <ranks> <args...>): results in ${WORK}/<name>
function(run name np)
  if(np EQUAL 1)
    set(cmd ${MFSI})
  else()
    set(cmd ${MPIEXEC} --allow-run-as-root --oversubscribe -np ${np} ${MFSI})
  endif()
  execute_process(COMMAND ${cmd} run ${ARGN} --out ${WORK}/${name} RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "${name} (${np} ranks): exit ${rc}\n${o}\n${e}")
  endif()
  file(READ ${WORK}/${name}/summary.json s)
  string(JSON ranks GET "${s}" ranks)
  if(NOT ranks EQUAL np)
    message(SEND_ERROR "${name}: summary says ${ranks} ranks, not ${np}")
  endif()
endfunction()

# same(<a> <b> <tolerance> <keys...>): each summary metric of run b within tolerance (relative) of run a
function(same a b tol)
  file(READ ${WORK}/${a}/summary.json sa)
  file(READ ${WORK}/${b}/summary.json sb)
  foreach(key ${ARGN})
    string(JSON x GET "${sa}" metrics ${key})
    string(JSON y GET "${sb}" metrics ${key})
    execute_process(COMMAND awk "BEGIN { d = ${x} - (${y}); if (d < 0) d = -d; a = ${x}; if (a < 0) a = -a; exit !(d <= ${tol} * a && a > 0) }"
      RESULT_VARIABLE ok)
    if(NOT ok EQUAL 0)
      message(SEND_ERROR "${b}: ${key} = ${y}, ${a} gives ${x} (tolerance ${tol} relative)")
    else()
      message(STATUS "${b}: ${key} = ${y} (${a}: ${x})")
    endif()
  endforeach()
endfunction()

set(cavity flexible-cavity --set mesh.blocks.0.cells=[12,10,1] --set mesh.blocks.1.cells=[12,2,1]
  --set time.endTime=1 ${tight})
run(cavity1 1 ${cavity} --set output.checkpoint.everySteps=3)
run(cavity2 2 ${cavity})
run(cavity2again 2 ${cavity})
set(compared cavity2)
if(NOT SHORT)
  run(cavity4 4 ${cavity})
  list(APPEND compared cavity4)
endif()
foreach(b ${compared})
  same(cavity1 ${b} 1e-10 membrane.bottom.centreUy membrane.bottom.maxVonMises fluid.max_velocity mesh.total_volume
    mesh.min_scaled_jacobian coupling.min_scaled_jacobian mesh.max_non_orthogonality_deg mesh.max_skewness
    mesh.min_cell_volume mesh.max_cell_volume)
  # The mean (0.04 degrees) is over faces nearly all orthogonal, whose angles, the acos of a cosine
  # next to 1, magnify the points' last digits (measured 4e-10).
  same(cavity1 ${b} 1e-8 mesh.mean_non_orthogonality_deg)
  same(cavity1 ${b} 0 coupling.mean_iterations coupling.max_iterations)
endforeach()

# The mesh motion by columns (lines of edges from the membrane to the lid, each traced across the
# ranks' parts): the same columns and answer on 2 (and 4) ranks as on one. The columns must act:
# the moved mesh differs from the solved motion's.
run(columns1 1 ${cavity} --set coupling.meshMotion.columns=true)
run(columns2 2 ${cavity} --set coupling.meshMotion.columns=true)
set(withColumns columns2)
if(NOT SHORT)
  run(columns4 4 ${cavity} --set coupling.meshMotion.columns=true)
  list(APPEND withColumns columns4)
endif()
foreach(b ${withColumns})
  same(columns1 ${b} 1e-10 membrane.bottom.centreUy fluid.max_velocity mesh.min_scaled_jacobian mesh.min_cell_volume)
  same(columns1 ${b} 0 coupling.mesh_motion_columns coupling.mean_iterations)
endforeach()
file(READ ${WORK}/cavity1/summary.json sa)
file(READ ${WORK}/columns1/summary.json sb)
string(JSON x GET "${sa}" metrics mesh.min_cell_volume)
string(JSON y GET "${sb}" metrics mesh.min_cell_volume)
string(JSON n GET "${sb}" metrics coupling.mesh_motion_columns)
execute_process(COMMAND awk "BEGIN { d = (${x}) - (${y}); if (d < 0) d = -d; exit !(d > 1e-5 * ${x}) }"
  RESULT_VARIABLE acts)
if(NOT acts EQUAL 0 OR NOT n EQUAL 22)
  message(SEND_ERROR "columns: ${n} (want 22), the smallest cell ${y} against ${x} without them")
endif()
# across_ranks(<run> <relation> <count>): how many columns run through more than one rank's nodes
function(across_ranks name relation count)
  file(READ ${WORK}/${name}/summary.json js)
  string(JSON a GET "${js}" metrics coupling.mesh_motion_columns_across_ranks)
  if(NOT a ${relation} ${count})
    message(SEND_ERROR "${name}: ${a} columns across ranks (want ${relation} ${count})")
  else()
    message(STATUS "${name}: ${a} columns across ranks")
  endif()
endfunction()
across_ranks(columns1 EQUAL 0)
foreach(b ${withColumns})
  across_ranks(${b} GREATER 0)  # the search handed lines from rank to rank
endforeach()

# Bitwise repeatable at a given rank count: steps.csv equal without its wall_s column.
function(rows_without_wall dir out)
  file(STRINGS ${dir}/steps.csv rows)
  set(kept "")
  foreach(r ${rows})
    string(REGEX REPLACE "^([^,]*,[^,]*,)[^,]*" "\\1" r "${r}")
    list(APPEND kept "${r}")
  endforeach()
  set(${out} "${kept}" PARENT_SCOPE)
endfunction()
rows_without_wall(${WORK}/cavity2 first)
rows_without_wall(${WORK}/cavity2again second)
list(LENGTH first n)
if(NOT n GREATER 10 OR NOT first STREQUAL second)
  message(SEND_ERROR "two runs on 2 ranks differ (or too few rows: ${n})")
endif()
file(GLOB f1 ${WORK}/cavity1/fields/*.h5)
file(GLOB f2 ${WORK}/cavity2/fields/*.h5)
list(LENGTH f2 nf)
if(NOT nf EQUAL 1)
  message(SEND_ERROR "cavity on 2 ranks: ${nf} field files")
endif()

set(piston piston --set time.endTime=0.05 ${tight} --set coupling.fsiTol=1e-13 --set coupling.maxFsiIter=40)
run(piston1 1 ${piston})
run(piston2 2 ${piston})
same(piston1 piston2 1e-9 bodies.body.piston.Fx bodies.body.piston.ax)

set(channelCells [24,8,16])
if(SHORT)
  set(channelCells [12,8,16])
endif()
set(channel membrane-channel --set time.endTime=0.06 --set mesh.blocks.0.cells=${channelCells} ${tight})
run(channel1 1 ${channel})
run(channel2 2 ${channel})
same(channel1 channel2 1e-9 fluid.bar.force_x fluid.max_velocity)
same(channel1 channel2 1e-8 bodies.body.frame.Fx)
same(channel1 channel2 1e-7 membrane.panelA.centreUx membrane.panelB.centreUx)
# The frame also carrying the mesh near it (coupling.meshMotion.bodies): each rank finds the bar's
# nodes on its part and weights its own nodes by their distance to all of them (gathered from the
# parts). The blend must act (measured: 7.5e-7 relative on the panel's centre against channel1,
# 3e-11 between 1 and 2 ranks).
set(reach --set coupling.meshMotion.bodies.frame.innerDistance=0.2
  --set coupling.meshMotion.bodies.frame.outerDistance=1)
run(reach1 1 ${channel} ${reach})
run(reach2 2 ${channel} ${reach})
same(reach1 reach2 1e-9 bodies.body.frame.Fx fluid.max_velocity membrane.panelA.centreUx)
file(READ ${WORK}/channel1/summary.json sa)
file(READ ${WORK}/reach1/summary.json sb)
string(JSON x GET "${sa}" metrics membrane.panelA.centreUx)
string(JSON y GET "${sb}" metrics membrane.panelA.centreUx)
execute_process(
  COMMAND awk "BEGIN { d = (${x}) - (${y}); if (d < 0) d = -d; exit !(d > 1e-8 * (${x} < 0 ? -(${x}) : ${x})) }"
  RESULT_VARIABLE acts)
if(NOT acts EQUAL 0)
  message(SEND_ERROR "the mesh's rigid blend around the frame changed nothing: panelA.centreUx ${y} against ${x}")
endif()

# run_pair(<name> <scene>): the scene on one rank and on 2 (runs <name>1 and <name>2), tight
# tolerances, to t = 2 s (0.5 s with SHORT).
function(run_pair name scene)
  set(end 2)
  if(SHORT)
    set(end 0.5)
  endif()
  run(${name}1 1 ${scene} --set time.endTime=${end} ${tight})
  run(${name}2 2 ${scene} --set time.endTime=${end} ${tight})
endfunction()
run_pair(balloon balloon)
same(balloon1 balloon2 1e-8 membrane.top.centreUy)
same(balloon1 balloon2 1e-10 coupling.chamber_volume)
same(balloon1 balloon2 1e-6 coupling.chamber_pressure)

# One region bounded by two membranes (tests/data/balloon_shared.yaml), each solved by its own
# rank, sharing the region's multiplier: the share rounds run on both ranks alike (each owner
# sends its membrane's multiplier and compliance). On 2 ranks as on one: the deflections to 1e-8,
# the region's volume to 1e-10, its pressure to 2e-6 (measured 1.1e-10, 5e-12, 3.4e-7 at 2 s).
run_pair(shared ${DATA}/balloon_shared.yaml)
same(shared1 shared2 1e-8 membrane.topA.centreUy membrane.topB.centreUy)
same(shared1 shared2 1e-10 coupling.chamber_volume)
same(shared1 shared2 2e-6 coupling.chamber_pressure)
# one_each(<run> <membrane> <membrane>): on 2 ranks each of the two membranes is solved by its own rank.
function(one_each name first second)
  file(READ ${WORK}/${name}/summary.json js)
  string(JSON a GET "${js}" metrics coupling.membrane.${first}.solved_on_rank)
  string(JSON b GET "${js}" metrics coupling.membrane.${second}.solved_on_rank)
  if(a EQUAL b OR a LESS 0 OR b LESS 0)
    message(SEND_ERROR "${name}: its membranes solved on ranks ${a} and ${b} (want one each)")
  endif()
endfunction()
one_each(shared2 topA topB)

# A closed chamber under a sprung lid that carries its membrane (tests/data/balloon_on_lid.yaml):
# the lid's faces on the chamber are summed over the ranks that own them (its rigid volume and the
# chamber's pressure on it). On 2 ranks as on one: the lid's rise and the deflection to 1e-8, the
# volume to 1e-10, the pressure to 1e-7 (measured 1.5e-9, 9e-10, 4e-12, 2.8e-9 at 2 s).
run_pair(lid ${DATA}/balloon_on_lid.yaml)
same(lid1 lid2 1e-8 bodies.body.lid.displacement membrane.top.centreUy)
same(lid1 lid2 1e-10 coupling.chamber_volume)
same(lid1 lid2 1e-7 coupling.chamber_pressure)
# The lumped gas chamber riding in the lid (tests/data/balloon_lumped_on_lid.yaml): the lid's rise
# and the deflection to 1e-8, the gas pressure to 1e-7.
run_pair(lumped_lid ${DATA}/balloon_lumped_on_lid.yaml)
same(lumped_lid1 lumped_lid2 1e-8 bodies.body.lid.displacement membrane.top.centreUy)
same(lumped_lid1 lumped_lid2 1e-7 coupling.chamber_pressure)
if(NOT SHORT)  # the instrumented builds run these scenes' group and blend code on one rank (stability.balloon)
  # The membrane blended between two sprung lids (tests/data/balloon_on_two_lids.yaml): the lids'
  # rises to 1e-8, the deflection to 1e-8, the volume to 1e-10, the pressure to 1e-7 (measured 5.4e-9,
  # 1.1e-9, 2e-12, 3.2e-8 at 2 s).
  run_pair(two_lids ${DATA}/balloon_on_two_lids.yaml)
  same(two_lids1 two_lids2 1e-8 bodies.body.lidL.displacement bodies.body.lidR.displacement membrane.top.centreUy)
  same(two_lids1 two_lids2 1e-10 coupling.chamber_volume)
  same(two_lids1 two_lids2 1e-7 coupling.chamber_pressure)
  # nested_pair(<name> <scene> [<body>]): a pair of the nested chambers, each membrane solved by its
  # own rank. On 2 ranks as on one: the body's travel and the deflections to 1e-8, the volumes to
  # 1e-10, the pressures to 2e-6 (the pressure at one instant of the filling's slosh is the most
  # sensitive: the piston's chambers' differ by 6.6e-7 while their displacements agree to 3e-10).
  function(nested_pair name scene)
    run_pair(${name} ${scene})
    set(moves membrane.lower.centreUy membrane.upper.centreUy)
    if(ARGC GREATER 2)
      list(APPEND moves bodies.body.${ARGV2}.displacement)
    endif()
    same(${name}1 ${name}2 1e-8 ${moves})
    same(${name}1 ${name}2 1e-10 coupling.chamber_volume.lower coupling.chamber_volume.upper)
    same(${name}1 ${name}2 2e-6 coupling.chamber_pressure.lower coupling.chamber_pressure.upper)
    one_each(${name}2 lower upper)
  endfunction()
  # A membrane between two closed regions (tests/data/balloon_nested.yaml): the two regions'
  # multipliers are solved together from both membranes' answers (measured at 2 s: the deflections
  # 5.6e-11 and 8.1e-11, the volumes 1.1e-12 and 2e-11, the pressures 1.4e-8 and 3.9e-8).
  nested_pair(nested ${DATA}/balloon_nested.yaml)
  # The same with chamber A's floor a sprung piston (tests/data/balloon_nested_on_piston.yaml): the
  # piston's faces on A are summed over the ranks that own them (measured: the deflections 2.7e-10
  # and 1.2e-10, the travel 6.3e-11, the volumes 6.9e-12 and 1.2e-12, the pressures 6.6e-7 and 6.1e-7).
  nested_pair(nested_piston ${DATA}/balloon_nested_on_piston.yaml piston)
  # ... and with the membrane between them mounted in a sprung divider (tests/data/
  # balloon_nested_on_divider.yaml): the divider's faces on both chambers summed over the ranks
  # (measured 4e-11 and 2.2e-11, 1.7e-10, 2.5e-12 and 1.4e-11, 1.8e-7 and 1.5e-7).
  nested_pair(nested_divider ${DATA}/balloon_nested_on_divider.yaml divider)
endif()

# The VAD pump with both chambers meshed (cases/vad-two-chambers.yaml: the air closed by the
# membrane's volume constraint, the mesh moved by 482 columns on both sides of the membrane, which
# cross the ranks' parts): its first 5 ms (1 with SHORT) with tight tolerances on 2 ranks as on one
# (measured: the air's pressure 5e-10, its volume 2e-12, the membrane's largest displacement 3e-7).
set(vadSteps 0.005)
if(SHORT)
  set(vadSteps 0.001)
endif()
set(vad vad-two-chambers --set time.endTime=${vadSteps} --set coupling.fsiTol=1e-7
  --set fluid.solvers.pressure.relTol=0 --set fluid.solvers.pressure.finalRelTol=0
  --set fluid.solvers.pressure.tolerance=1e-12 --set fluid.solvers.momentum.relTol=0
  --set fluid.solvers.momentum.tolerance=1e-12 --set fluid.pimple.outerTolerance=1e-10
  --set fluid.pimple.outerCorrectors=50)
run(vad1 1 ${vad})
run(vad2 2 ${vad})
same(vad1 vad2 1e-8 coupling.chamber_pressure fluid.max_velocity mesh.min_scaled_jacobian)
same(vad1 vad2 1e-10 coupling.chamber_volume)
same(vad1 vad2 1e-5 membrane.membrane.maxDisplacement membrane.membrane.centreDeflection)
same(vad1 vad2 0 coupling.mesh_motion_columns)
across_ranks(vad2 GREATER 0)

# Two screens, each solved only by the rank that owns its cells (one on each rank), the other
# rank receiving the answer: the same as one rank's to 1e-9 with tight tolerances.
set(screens two-screens --set mesh.blocks.0.cells=[16,8,8] --set time.endTime=0.06 ${tight})
run(screens1 1 ${screens})
run(screens2 2 ${screens})
same(screens1 screens2 1e-9 membrane.screenA.maxDisplacement membrane.screenB.maxDisplacement fluid.max_velocity)
file(READ ${WORK}/screens2/summary.json js)
string(JSON a GET "${js}" metrics coupling.membrane.screenA.solved_on_rank)
string(JSON b GET "${js}" metrics coupling.membrane.screenB.solved_on_rank)
string(JSON n GET "${js}" metrics coupling.membranes_solved_on_rank0)
if(a EQUAL b OR a LESS 0 OR b LESS 0 OR NOT n EQUAL 1)
  message(SEND_ERROR "two screens on 2 ranks: solved on ranks ${a} and ${b}, ${n} on rank 0 (want one each)")
endif()

# Checkpoints every 3 steps, the last 2 kept: steps 6 and 9 on both ranks, step 3 gone from both.
run(saved 2 ${cavity} --set output.checkpoint.everySteps=3)
foreach(f checkpoint_000000006.h5 checkpoint_000000006.rank1.h5 checkpoint_000000009.rank1.h5)
  if(NOT EXISTS ${WORK}/saved/checkpoints/${f})
    message(SEND_ERROR "2 ranks: no checkpoints/${f}")
  endif()
endforeach()
foreach(f checkpoint_000000003.h5 checkpoint_000000003.rank1.h5)
  if(EXISTS ${WORK}/saved/checkpoints/${f})
    message(SEND_ERROR "2 ranks: checkpoints/${f} was not pruned (keep: 2)")
  endif()
endforeach()
run(continued 2 --restart ${WORK}/saved/checkpoints/checkpoint_000000006.h5)
rows_without_wall(${WORK}/saved whole)
rows_without_wall(${WORK}/continued rest)
list(SUBLIST whole 7 -1 tail)  # header and steps 1-6 dropped
list(REMOVE_AT rest 0)
list(LENGTH rest nr)
if(NOT nr EQUAL 4 OR NOT tail STREQUAL rest)
  message(SEND_ERROR "a restart on 2 ranks from step 6 differs from the run it continues (${nr} rows):\n${rest}\n${tail}")
endif()
# A restart on 3 ranks of the 2-rank checkpoint: the state carried by global ids, the end of the
# run as the uninterrupted one's to the solvers' tolerance (measured: 12 digits).
if(NOT SHORT)
  run(three 3 --restart ${WORK}/saved/checkpoints/checkpoint_000000006.h5)
  same(saved three 1e-9 membrane.bottom.centreUy fluid.max_velocity membrane.bottom.maxVonMises)
endif()
# ... and on one rank (measured 4e-15), and one rank's checkpoint on 2 ranks (measured 3e-15).
run(one 1 --restart ${WORK}/saved/checkpoints/checkpoint_000000006.h5)
same(saved one 1e-9 membrane.bottom.centreUy fluid.max_velocity membrane.bottom.maxVonMises)
run(two 2 --restart ${WORK}/cavity1/checkpoints/checkpoint_000000006.h5)
same(cavity1 two 1e-9 membrane.bottom.centreUy fluid.max_velocity membrane.bottom.maxVonMises)
# Each rank's checkpoint file holds its part's moved points (no gather to rank 0); a checkpoint
# from before that (the whole mesh's points in rank 0's file) still continues, on 2 ranks.
set(python /usr/bin/python3)
if(NOT EXISTS ${python})
  find_program(python python3 REQUIRED)
endif()
set(points ${CMAKE_CURRENT_LIST_DIR}/support/checkpoint_points.py)
execute_process(COMMAND ${python} ${points} parts ${WORK}/saved/checkpoints/checkpoint_000000006.h5 2
  ${WORK}/cavity1/checkpoints/checkpoint_000000006.h5 RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(rc EQUAL 77)
  message(STATUS "checkpoint points not inspected (no h5py): ${o}")
else()
  if(NOT rc EQUAL 0)
    message(SEND_ERROR "the 2-rank checkpoint's points:\n${o}${e}")
  endif()
  file(COPY ${WORK}/cavity1/ DESTINATION ${WORK}/earlier)
  execute_process(COMMAND ${python} ${points} legacy ${WORK}/earlier/checkpoints/checkpoint_000000006.h5
    RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "making a checkpoint of the earlier layout: ${o}${e}")
  endif()
  run(legacy 2 --restart ${WORK}/earlier/checkpoints/checkpoint_000000006.h5)
  same(cavity1 legacy 1e-9 membrane.bottom.centreUy fluid.max_velocity membrane.bottom.maxVonMises)
endif()

# The map `mfsi partition` writes is the one a run computes.
execute_process(COMMAND ${MFSI} partition ${cavity} -n 2 --out ${WORK}/map2.txt RESULT_VARIABLE rc OUTPUT_VARIABLE o
  ERROR_VARIABLE e)
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "mfsi partition: exit ${rc}\n${o}\n${e}")
endif()
run(mapped 2 ${cavity} --partition ${WORK}/map2.txt)
rows_without_wall(${WORK}/mapped mappedRows)
if(NOT mappedRows STREQUAL first)
  message(SEND_ERROR "the run on mfsi partition's map differs from the run that computed it")
endif()
file(STRINGS ${WORK}/map2.txt map)
list(TRANSFORM map REPLACE "^[0-9]+$" "7" AT 4)  # line 5: a rank this run does not have
string(REPLACE ";" "\n" map "${map}")
file(WRITE ${WORK}/bad.txt "${map}\n")
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np 2 ${MFSI} run ${cavity}
  --partition ${WORK}/bad.txt --out ${WORK}/bad RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
string(REGEX MATCHALL "bad.txt:5: '7' is not a rank" lines "${e}")
list(LENGTH lines nl)
if(NOT rc EQUAL 2 OR NOT nl EQUAL 1)
  message(SEND_ERROR "a map with a bad line 5: exit ${rc}, ${nl} messages:\n${e}")
endif()
# A map that puts the membrane's cells on two ranks is refused: a rank holds a membrane's (or a
# baffle's) faces only with all of its cells.
set(split "")
foreach(c RANGE 143)
  math(EXPR r "${c} % 2")
  string(APPEND split "${r}\n")
endforeach()
file(WRITE ${WORK}/split.txt "${split}")
execute_process(COMMAND ${MPIEXEC} --allow-run-as-root --oversubscribe -np 2 ${MFSI} run ${cavity}
  --partition ${WORK}/split.txt --out ${WORK}/split RESULT_VARIABLE rc OUTPUT_VARIABLE o ERROR_VARIABLE e)
if(NOT rc EQUAL 2 OR NOT e MATCHES "split.txt: the cells along membrane patch 'bottom' are on ranks")
  message(SEND_ERROR "a map that splits the membrane: exit ${rc}\n${e}")
endif()
