#include "dualgrid/eval/point_metrics.hpp"

#include "json_util.hpp"

namespace dualgrid::eval {

using detail::OptFromJson;
using detail::OptToJson;

PointMetrics PointClassificationAccumulator::Result() const {
  PointMetrics m = m_;
  const double tp = static_cast<double>(m.true_positives);
  if (m.true_positives + m.false_positives > 0) m.precision = tp / (tp + m.false_positives);
  if (m.true_positives + m.false_negatives > 0) m.recall = tp / (tp + m.false_negatives);
  if (m.precision && m.recall && *m.precision + *m.recall > 0.0)
    m.f1 = 2.0 * *m.precision * *m.recall / (*m.precision + *m.recall);
  return m;
}

void to_json(nlohmann::json& j, const PointMetrics& m) {
  j = nlohmann::json{{"true_positives", m.true_positives},
                     {"false_positives", m.false_positives},
                     {"false_negatives", m.false_negatives},
                     {"true_negatives", m.true_negatives},
                     {"outside", m.outside},
                     {"frames", m.frames},
                     {"precision", OptToJson(m.precision)},
                     {"recall", OptToJson(m.recall)},
                     {"f1", OptToJson(m.f1)}};
}

void from_json(const nlohmann::json& j, PointMetrics& m) {
  j.at("true_positives").get_to(m.true_positives);
  j.at("false_positives").get_to(m.false_positives);
  j.at("false_negatives").get_to(m.false_negatives);
  j.at("true_negatives").get_to(m.true_negatives);
  j.at("outside").get_to(m.outside);
  j.at("frames").get_to(m.frames);
  m.precision = OptFromJson(j, "precision");
  m.recall = OptFromJson(j, "recall");
  m.f1 = OptFromJson(j, "f1");
}

}  // namespace dualgrid::eval
