# Each bad invocation of rp-model must print exactly one line on stderr and exit with status 2
# (and within the test's timeout: a kinematic loop used to hang it). DATA: tests/model/data.
# Each case is one string of space-separated arguments (a CMake list of ';'-separated words would
# be flattened into one long list, one word per run).
set(cases
  "--robot nosuchrobot fk --q 0,0,0,0,0,0"
  "--robot puma560 fk --q 0,0,0"
  "--robot puma560 fk --q 0,0,x,0,0,0"
  "--robot puma560 fk"
  "--robot puma560 dance --q 0,0,0,0,0,0"
  "--robot puma560 ik --pose 1,0,0,5,0,1,0,0,0,0,1,0,0,0,0,1"
  "--robot puma560 ik --pose 1,2,3"
  "--robot missing.urdf fk --q 0"
  "--robot puma560 --tip link3 fk --q 0,0,0,0,0,0"
  "fk --q 0,0,0,0,0,0"
  # Issue 20: values that are not finite numbers, poses that are not rigid transforms.
  "--robot puma560 fk --q 0,0,nan,0,0,0"
  "--robot puma560 fk --q 0,0,0,inf,0,0"
  "--robot puma560 fk --q 0,0,0,0,1e999,0"
  "--robot puma560 rnea --q 0,0,0,0,0,0 --qd 0,0,0,0,0,0 --qdd 0,-nan,0,0,0,0"
  "--robot wam7 ik --pose 2,0,0,0.3,0,2,0,0,0,0,2,0.5,0,0,0,1"
  "--robot wam7 ik --pose 0,0,0,0.3,0,0,0,0,0,0,0,0.5,0,0,0,1"
  "--robot puma560 ik --pose 2,0,0,0.3,0,2,0,0,0,0,2,0.5,0,0,0,1"
  "--robot wam7 ik --pose 1,0,0,0.3,0,1,0,0,0,0,-1,0.5,0,0,0,1"
  "--robot wam7 ik --pose 1,0,0,0.3,0,1,0,0,0,0,1,0.5,0,0,1,1"
  "--robot wam7 ik --pose 1,0,0,nan,0,1,0,0,0,0,1,0.5,0,0,0,1"
  # Issue 19: URDF files with a kinematic loop (used to hang) or a NaN mass (used to load).
  "--robot ${DATA}/kinematic_loop.urdf fk --q 0,0"
  "--robot ${DATA}/nan_mass.urdf gravity --q 0"
  # A finite origin too far for a robot (1e308 m): the inertia and fd commands printed null with status 0.
  "--robot ${DATA}/huge_origin.urdf inertia --q 0 => huge_origin.urdf: joint 'j': <origin> xyz '0 0 1e308' has a coordinate larger than 1e6 m in magnitude$"
  # Issue 23: an MJCF export needs the inertial data of every moving link.
  "--robot ${DATA}/no_inertia.urdf mjcf"
  # Issue 20: joint values by name: an unknown name, a joint left out, names mixed with positions.
  "--robot ${DATA}/ur_like.urdf fk --q nosuch_joint=0"
  "--robot puma560 fk --q joint1=0,joint2=0"
  "--robot puma560 fk --q joint1=0,0,0,0,0,0"
  # Issue 20: --offchain names a joint the arm has no moving joint off the chain of, a value that is
  # not a finite number or outside the joint's limits, a joint twice, or a robot without a URDF.
  "--robot ${DATA}/jaw_arm.urdf --offchain nosuch=0 fk --q 0,0,0,0,0,0 => --offchain: there is no joint 'nosuch' \\(moving joints off the chain: jointGripper\\) in .*jaw_arm.urdf$"
  "--robot ${DATA}/jaw_arm.urdf --offchain jointGripper=0.5 fk --q 0,0,0,0,0,0 => --offchain: joint 'jointGripper': 0.5 rad is outside its limits -1.57 .. 0 rad"
  "--robot ${DATA}/jaw_arm.urdf --offchain jointGripper=nan fk --q 0,0,0,0,0,0 => --offchain: 'nan' is not a finite number"
  "--robot ${DATA}/jaw_arm.urdf --offchain jointGripper fk --q 0,0,0,0,0,0 => --offchain: 'jointGripper' is not a name=value pair"
  "--robot ${DATA}/jaw_arm.urdf --offchain joint2=0.1 fk --q 0,0,0,0,0,0 => --offchain: joint 'joint2' is a joint of the arm, not off the chain"
  "--robot ${DATA}/jaw_arm.urdf --offchain jointGripper=-1,jointGripper=-0.5 fk --q 0,0,0,0,0,0 => --offchain: joint 'jointGripper' is given twice"
  "--robot puma560 --offchain jointGripper=0 fk --q 0,0,0,0,0,0 => --offchain applies to URDF robots only"
  # An option given twice, or one the command does not read: the last --q used to win, and fk
  # --tau or puma560 ik --seed (never parsed) were taken without a word.
  "--robot puma560 fk --q 0,0,0,0,0,0 --q 1,1,1,1,1,1 => --q is given twice$"
  "--robot puma560 rnea --q 0,0,0,0,0,0 --qd 0,0,0,0,0,0 --qdd 0,0,0,0,0,0 --friction --friction => --friction is given twice$"
  "--robot puma560 fk --q 0,0,0,0,0,0 --tau 1,2 => --tau does not apply to fk$"
  "--robot puma560 inertia --q 0,0,0,0,0,0 --friction => --friction does not apply to inertia$"
  "--robot puma560 ik --pose 0,0,1,0.5963,0,1,0,-0.15005,-1,0,0,0.65748,0,0,0,1 --seed 0,0,0,0,0,0x => --seed does not apply to puma560 ik")
set(count 0)
foreach(args IN LISTS cases)
  # "ARGS => REGEX": the message must also match REGEX.
  set(expect "")
  string(FIND "${args}" " => " arrow)
  if(NOT arrow EQUAL -1)
    math(EXPR after "${arrow} + 4")
    string(SUBSTRING "${args}" ${after} -1 expect)
    string(SUBSTRING "${args}" 0 ${arrow} args)
  endif()
  set(shown "${args}")
  separate_arguments(argv UNIX_COMMAND "${shown}")
  execute_process(COMMAND ${PROGRAM} ${argv} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err TIMEOUT 60)
  string(STRIP "${err}" err)
  string(FIND "${err}" "\n" newline)
  if(NOT rc EQUAL 2 OR NOT newline EQUAL -1 OR NOT err MATCHES "^rp-model: ")
    message(FATAL_ERROR "rp-model ${shown}: status ${rc}, stderr '${err}'")
  endif()
  if(NOT expect STREQUAL "" AND NOT err MATCHES "${expect}")
    message(FATAL_ERROR "rp-model ${shown}: stderr '${err}' does not match '${expect}'")
  endif()
  message("rp-model ${shown} -> ${err}")
  math(EXPR count "${count} + 1")
endforeach()
if(NOT count EQUAL 39)
  message(FATAL_ERROR "${count} cases ran, expected 39")
endif()
