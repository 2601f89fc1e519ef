// mft-cyclone listen: any topic of the registry, read with Cyclone DDS; per topic the samples, the ticks, and the
// range of one checked value (the first floating-point field unless the topic names one below).
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "cyclone_common.hpp"

namespace {

// The value a listener checks, in the units the interop test reads; other topics: their first double field.
struct CheckedValue {
  const char *topic, *field, *label;
  size_t count;
};
constexpr CheckedValue kChecked[] = {{"SensorData", "actuated_pos", "actuated_pos [rad]", 4},
                                     {"JointCommand", "tau", "tau [N m]", 4},
                                     {"Reference", "base_z", "base_z [m]", 1}};

struct TopicStats {
  std::string name, field, label;  // field: the checked value's field, empty for the first double field
  size_t count = 0;                // how many of its elements (0: all)
  long samples = 0;
  unsigned long long first_tick = 0, last_tick = 0;
  long tick_decreases = 0, nonfinite = 0;
  double lo = HUGE_VAL, hi = -HUGE_VAL;

  void add(unsigned long long tick, const double *values, size_t n) {
    if (samples > 0 && tick < last_tick) tick_decreases++;
    if (samples == 0) first_tick = tick;
    last_tick = tick;
    samples++;
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(values[i])) {
        nonfinite++;
        continue;
      }
      if (values[i] < lo) lo = values[i];
      if (values[i] > hi) hi = values[i];
    }
  }
  void print(bool json, bool last) const {
    if (json) {
      printf("  \"%s\": {\"samples\": %ld, \"first_tick\": %llu, \"last_tick\": %llu, \"tick_decreases\": %ld, "
             "\"nonfinite\": %ld, \"value\": \"%s\", \"min\": %.9g, \"max\": %.9g}%s\n",
             name.c_str(), samples, first_tick, last_tick, tick_decreases, nonfinite, label.c_str(),
             samples ? lo : 0.0, samples ? hi : 0.0, last ? "" : ",");
    } else {
      printf("%-13s %7ld samples, ticks %llu..%llu, %ld decreases, %ld non-finite, %s in [%.4g, %.4g]\n", name.c_str(),
             samples, first_tick, last_tick, tick_decreases, nonfinite, label.c_str(), samples ? lo : 0.0,
             samples ? hi : 0.0);
    }
  }
};

template <class M, class = void>
struct HasTick : std::false_type {};
template <class M>
struct HasTick<M, std::void_t<decltype(std::declval<M>().tick)>> : std::true_type {};

// The sample's tick (an event's seq) and its checked value.
template <class M>
void addSample(TopicStats *s, const M &m) {
  unsigned long long tick = 0;
  if constexpr (HasTick<M>::value) tick = m.tick;
  else tick = m.seq;
  const double *values = nullptr;
  size_t n = 0;
  mft::cyclone::visitFields(m, [&](const char *name, const auto &v) {
    using V = std::remove_cv_t<std::remove_reference_t<decltype(v)>>;
    if (values || !(s->field.empty() || s->field == name)) return;
    if constexpr (std::is_same_v<V, double>) {
      values = &v, n = 1;
    } else if constexpr (std::is_array_v<V> && std::is_same_v<std::remove_extent_t<V>, double>) {
      values = v, n = std::extent_v<V>;
    }
    if (values && s->field.empty()) s->label = name;
  });
  s->add(tick, values, s->count && s->count < n ? s->count : n);
}

struct Listened {
  TopicStats stats;
  dds_entity_t reader = 0;
  void (*take)(Listened *) = nullptr;
};

// Takes every sample waiting on the reader.
template <class M>
void takeAll(Listened *l) {
  void *samples[16] = {};
  dds_sample_info_t infos[16];
  const int n = dds_take(l->reader, samples, infos, 16, 16);
  for (int i = 0; i < n; ++i)
    if (infos[i].valid_data) addSample(&l->stats, *static_cast<const M *>(samples[i]));
  if (n > 0) dds_return_loan(l->reader, samples, n);
}

dds_entity_t make_reader(dds_entity_t participant, const dds_topic_descriptor_t *desc, const std::string &name,
                         bool reliable) {
  dds_entity_t topic = dds_create_topic(participant, desc, name.c_str(), NULL, NULL);
  if (topic < 0) return topic;
  dds_qos_t *qos = dds_create_qos();
  dds_qset_reliability(qos, reliable ? DDS_RELIABILITY_RELIABLE : DDS_RELIABILITY_BEST_EFFORT, DDS_SECS(1));
  dds_qset_history(qos, DDS_HISTORY_KEEP_LAST, 64);
  dds_entity_t reader = dds_create_reader(participant, topic, qos, NULL);
  dds_delete_qos(qos);
  return reader;
}

// A reader for topic `name` of the registry; false for an unknown name.
bool openTopic(dds_entity_t participant, const std::string &name, const char *prefix, Listened *l) {
  l->stats.name = name;
  l->stats.label = "";
  for (const auto &c : kChecked)
    if (name == c.topic) l->stats.field = c.field, l->stats.label = c.label, l->stats.count = c.count;
#define MFT_CYCLONE_OPEN(Name, snake, event, tick)                                                        \
  if (name == #Name) {                                                                                     \
    l->reader = make_reader(participant, &mft_msg_dds__##Name##__desc, std::string(prefix) + snake, event); \
    l->take = takeAll<mft_msg_dds__##Name##_>;                                                            \
    return true;                                                                                           \
  }
  MFT_CYCLONE_TOPICS(MFT_CYCLONE_OPEN)
#undef MFT_CYCLONE_OPEN
  return false;
}

bool openTopics(dds_entity_t participant, const char *prefix, const char *topics, std::vector<std::unique_ptr<Listened>> *out) {
  std::string list = topics;
  for (size_t at = 0; at <= list.size();) {
    const size_t comma = std::min(list.find(',', at), list.size());
    const std::string name = list.substr(at, comma - at);
    at = comma + 1;
    if (name.empty()) continue;
    out->push_back(std::make_unique<Listened>());
    if (!openTopic(participant, name, prefix, out->back().get())) {
      fprintf(stderr, "mft-cyclone: unknown topic %s (idl/topics.yaml)\n", name.c_str());
      return false;
    }
    if (out->back()->reader < 0) {
      fprintf(stderr, "mft-cyclone: cannot create the readers\n");
      return false;
    }
  }
  return !out->empty();
}

}  // namespace

int cmd_listen(int domain, double seconds, long min_samples, const char *prefix, const char *topics, bool json) {
  dds_entity_t participant = make_participant(domain);
  if (participant < 0) {
    fprintf(stderr, "mft-cyclone: cannot create a participant on domain %d: %s\n", domain, dds_strretcode(-participant));
    return EXIT_USAGE;
  }
  std::vector<std::unique_ptr<Listened>> listened;
  if (!openTopics(participant, prefix, topics, &listened)) {
    dds_delete(participant);
    return EXIT_USAGE;
  }
  dds_entity_t waitset = dds_create_waitset(participant);
  for (size_t i = 0; i < listened.size(); ++i)
    dds_waitset_attach(waitset, dds_create_readcondition(listened[i]->reader, DDS_ANY_STATE), (dds_attach_t)i);
  const double t_end = now_s() + seconds;
  auto enough = [&] {
    for (const auto &l : listened)
      if (l->stats.samples < min_samples) return false;
    return min_samples > 0;
  };
  while (now_s() < t_end && !enough()) {
    dds_waitset_wait(waitset, NULL, 0, DDS_MSECS(50));
    for (auto &l : listened) l->take(l.get());
  }
  if (json) printf("{\n \"domain\": %d,\n \"topics\": {\n", domain);
  for (size_t i = 0; i < listened.size(); ++i) listened[i]->stats.print(json, i + 1 == listened.size());
  if (json) printf(" }\n}\n");
  dds_delete(participant);
  for (const auto &l : listened)
    if (l->stats.samples == 0) {
      fprintf(stderr, "mft-cyclone: no samples on %s within %.1f s\n", l->stats.name.c_str(), seconds);
      return EXIT_NO_DATA;
    }
  return EXIT_OK;
}
