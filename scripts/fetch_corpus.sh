#!/usr/bin/env bash
# Obtains the preprocessing corpus (experiments/studies/preprocess, "Corpus"):
# 40 closed or nearly closed surface meshes of CGAL's demo data (data/meshes in
# the data.tar.gz of Debian's libcgal-demo package, CGAL 5.5.1), scans and CAD
# parts from 76 to 88,928 triangles, verified by SHA-256 and cached in
# data/corpus/ (never committed). Idempotent. Usage: scripts/fetch_corpus.sh [DIR]
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out="${1:-$root/data/corpus}"

declare -A SHA=(
  [armadillo.off]=6f7f3ca1abc506569466b72f2f59d49493a284e7376d7a7e23c08115ec8cec4e
  [ChineseDragon-10kv.off]=f633bdfaac7a0f99e0fab668c34862f0c26f341cfdb4665bab282d79b788db02
  [bunny00.off]=ab651cb04955c161efaeb079035a1e5e1f0e0d1f816a2df67beaea68f393ff2b
  [bull.off]=5c7b9631f8c278c12b30c0eea0b72da871504674516daf7d7eaaf5fa4154224a
  [camel.off]=9ac960a9fee27e6fcc6baaa2340260834625084ee20f4a97194212404e650a22
  [cow.off]=1c5a25c3047fc6b14dd0c962d3562b1796671422ab4634f9d46f9f23814cd54a
  [elephant.off]=be4e1ea68f5f840a3d2ada69d828222e76a57d9e25b21e19a9deacd3f2328e02
  [elk.off]=7f1229fd3de0b4fc0884bbbfbd056a57ff0cb0f7afd71b5168a84209cc585abb
  [femur.off]=75d208fabf7a7b134cfcf2171bad68c331e3bff55309ffe38a01a7b31352fbc6
  [hand.off]=cfcf1562726167ca704a091a8651bfd1d72f6eb96b4b2819321f0520721b35c7
  [man.off]=9f04482c1028de539f02319c476d6c95141e9fbc389e9d469041ab63096de5d4
  [triceratops.off]=0fb444933884486a09eb4329a832f15ab792590f2a5bb75385d157e654ddbf5c
  [refined_elephant.off]=a170eed4ef33ef412a72b824d791f69ea59ee5f5a7c12dc1ae9077b6eb030650
  [bones.off]=004bd26f0029910eb2e2fd38b7ca11ea05dd4182e247c0fb778533b860dd7ab2
  [eight.off]=58fa129fbd64d519034b12c73ecb463ae55832710aa34fddd0504debd044f71d
  [blobby.off]=ab217f67fefdf8a8e01563d09135f05ab02330064a3c0180570546887d01b7f1
  [knot1.off]=13d9d2f3459189630680dad6a3b5528d5cc794967b791580a0e1f6642903d030
  [knot2.off]=6c90e93f1a966abd73847d40909a90c0b2067affdd471a27b50c2d4416142c06
  [anchor.off]=5009b3400b73ef199b6ac9a24a27f4f76e1aa7b71d957a50cb6dcbe09868ff3b
  [dragknob.off]=4411436ff04757c16ad1c08d631c86ef7e968f1e026193e668c66a19951ca10c
  [joint.off]=a412da1a4b90a1d018d44e0b06307ee692da4afd255975d2a93945e091098649
  [oblong.off]=1024a074f8ff0896c3a7ab5bcac72b6f03a69ab71b2fbf3edbd206b2acbd928e
  [ellipsoid.off]=6f3271c0c9d8398c0ad1399230fa7f7fc1b20c90116d44b7ddbd2e5c42fb7470
  [retinal.off]=02547bcd1f28149862ff28056614418c0fca73033dfec1a07e8e91e4c78544b7
  [diplodocus.off]=661fdac29eca4b205e354da112b3cbfd08dcfae07df989234b71421e62521c96
  [head.off]=75aecfdbf9c0386dd839f5bf0322fb5a889ed7efd31d040f125e383041b4b919
  [mannequin-devil.off]=9424b7132b58766984051fb7757543e88972f91fe7e9565d4e5b715b204f74a5
  [mushroom.off]=03768b314714676d9305361c7c124be3b2c991c59fe8c752a49047115b4dfa00
  [lion-head.off]=cf159eeb12a3f3f345e57448693e9f0d115f3f6f38fd1d4519b336cede849289
  [fandisk.off]=edffb263f037b023757259befd5532fccb48bdc3c35a1da2e11e235a647bd050
  [cheese.off]=713ace843a5f0a8cc78a16ed0cedd5a5a0a2897d4bff02ac833a3b7e9382efb4
  [couplingdown.off]=01fc9017b44a803b1130f8f5d51f0c7d8bbfa27b908f5166c498fe21e57f2284
  [rotor.off]=8db85ca5041eef6d952e48f0553a25fddb42f237b80a37b7aff096b8df3aca32
  [pinion_small.off]=f52e7546230062d30b1998e601bb5228f132cdfd81a1994433b7bffe50fc5d62
  [spool.off]=84ec2367becf6994f96055fa88aaf3a00df1fdd84bd0fa615bdc043c9944b7b1
  [cube-meshed.off]=5244c3f5f3eab5011aa44fd09d2702be91defbbee9b58e01e2aca4e9937c3c8a
  [cross.off]=712151027be1e259be1a4049a383ad8884ced0282d4c64e75d0cc4d24e6005ab
  [u.off]=f2f3e8c8aa64c2e4caebef5c676097a12a48e3c1337c544c5c7d1201ab982592
  [part.off]=ffec9fae51770a524bd973724bb69babf3cae11ef7564fb630790cb64a75b00b
  [turbine.off]=8ae52b6b325a05e0755983706ab55aba0f42d3ea0569dd29b33cdcb16c20f4c8
)

. "$root/scripts/cgal_demo_meshes.sh"
fetch_cgal_demo_meshes "$out" "the corpus (about 24 MB)"
