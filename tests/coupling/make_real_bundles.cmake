# CTest fixture "real_bundles" (cmake -P): preprocesses the real meshes into
# a build-folder cache for the tests that need the scenes' trees
# (ConservativeDefaults.*, LinkEvaluator.EqualsReferenceOnDragonBundles).
#   -D PREPROCESS=<icd-preprocess> -D DATA=<meshes> -D OUT=<folder>
#   -D SIZES=depth:branching,...   (sphere-tree shapes, e.g. 3:10 -> ~1,100 spheres)
# A bundle is made again when it is missing or older than icd-preprocess.
# No shell: every path is one argument of execute_process.
foreach(var PREPROCESS DATA OUT SIZES)
  if(NOT DEFINED ${var})
    message(FATAL_ERROR "make_real_bundles.cmake: -D ${var}=... missing")
  endif()
endforeach()
string(REPLACE "," ";" SIZES "${SIZES}")
file(MAKE_DIRECTORY "${OUT}")
foreach(mesh bunny00 ChineseDragon-10kv)
  if(NOT EXISTS "${DATA}/${mesh}.off")
    message(FATAL_ERROR "make_real_bundles.cmake: ${DATA}/${mesh}.off missing "
                        "(scripts/fetch_meshes.sh fetches the meshes)")
  endif()
  foreach(size IN LISTS SIZES)
    string(REPLACE ":" ";" db "${size}")
    list(GET db 0 depth)
    list(GET db 1 branching)
    set(folder "${OUT}/${mesh}-d${depth}b${branching}")
    if(EXISTS "${folder}/bundle.icdb" AND NOT "${PREPROCESS}" IS_NEWER_THAN "${folder}/bundle.icdb")
      message(STATUS "${folder}: up to date")
      continue()
    endif()
    file(REMOVE_RECURSE "${folder}" "${folder}.part")
    string(TIMESTAMP t0 "%s")
    execute_process(
      COMMAND "${PREPROCESS}" "${DATA}/${mesh}.off" -o "${folder}.part" -q
              --coarse-tets 1500 --sphere-depth ${depth} --sphere-branching ${branching}
      RESULT_VARIABLE rc)
    if(NOT rc EQUAL 0)
      file(REMOVE_RECURSE "${folder}.part")
      message(FATAL_ERROR "icd-preprocess ${mesh} (depth ${depth}, branching ${branching}) failed: ${rc}")
    endif()
    file(RENAME "${folder}.part" "${folder}")
    string(TIMESTAMP t1 "%s")
    math(EXPR dt "${t1} - ${t0}")
    message(STATUS "${folder}: made in ${dt} s")
  endforeach()
endforeach()
