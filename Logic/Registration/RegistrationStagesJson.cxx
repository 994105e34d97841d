#include "Registration/RegistrationStagesJson.h"

namespace fct {

nlohmann::ordered_json RegistrationStagesJson::write(const RegistrationResult& result) {
  nlohmann::ordered_json stages = nlohmann::ordered_json::array();
  for (const StageReport& s : result.stages) {
    nlohmann::ordered_json kept = nlohmann::ordered_json::object();
    for (std::size_t v = 0; v < s.keptFraction.size() && v < result.viewNames.size(); ++v) {
      kept[result.viewNames[v]] = s.keptFraction[v];
    }
    stages.push_back({{"name", s.name},
                      {"metric", s.metric},
                      {"level", s.level},
                      {"search", s.search},
                      {"seconds", s.seconds},
                      {"drrs", s.drrs},
                      {"fallback_rays", s.fallbackRays},
                      {"evaluations", s.evaluations},
                      {"start_similarity", s.startSimilarity},
                      {"similarity", s.similarity},
                      {"kept_fraction", std::move(kept)},
                      {"cancelled", s.cancelled}});
  }
  return stages;
}

}  // namespace fct
