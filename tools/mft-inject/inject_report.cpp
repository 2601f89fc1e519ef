// mft-inject's report: what happened to the participant, the writer and each listened topic, as text or JSON.
#include <cstdio>

#include "common/json_writer.hpp"
#include "tools/mft-inject/inject_session.hpp"

namespace mft::inject {

namespace {

// Per listened topic: the JSON object and the text lines.
void listenReport(const std::map<std::string, std::unique_ptr<Listener>>& listeners, std::string* json, std::string* text) {
  config::JsonWriter w;
  w.beginObject();
  for (const auto& [t, l] : listeners) {
    std::lock_guard<std::mutex> lock(l->stats.mutex);
    w.key(t).beginObject().field("matched_writers", l->matched()).field("received", l->stats.received.load());
    w.field("nonfinite", l->stats.nonfinite.load()).field("first_tick", l->stats.first_tick);
    w.field("last_tick", l->stats.last_tick).fixedField("max_gap_ms", static_cast<double>(l->stats.max_gap_ns) * 1e-6, 3);
    w.field("max_gap_end_ns", l->stats.max_gap_end_ns).field("first_ns", l->stats.first_ns);
    w.field("last_ns", l->stats.last_ns).endObject();
    char buf[400];
    std::snprintf(buf, sizeof buf, "  %-16s matched writers %d, received %llu (non-finite %llu), largest gap %.1f ms\n",
                  t.c_str(), l->matched(), static_cast<unsigned long long>(l->stats.received.load()),
                  static_cast<unsigned long long>(l->stats.nonfinite.load()), static_cast<double>(l->stats.max_gap_ns) * 1e-6);
    *text += buf;
  }
  *json = w.endObject().str();
}

}  // namespace

void Session::report(const Options& o) const {
  std::string listen_json, listen_text;
  listenReport(listeners, &listen_json, &listen_text);
  const int matched_readers = publisher ? publisher->matched() : 0;
  const unsigned long long written = publisher ? static_cast<unsigned long long>(publisher->written()) : 0ULL;
  if (o.json) {
    config::JsonWriter w;
    w.beginObject().field("domain", o.domain).key("identity");
    if (o.security.enabled()) w.value(o.security.identity);
    else w.null();
    w.field("participant", participant_status).field("publish", o.publish_topic).field("writer", writer_status);
    w.field("value", o.value).field("follow", o.follow).field("matched_readers", matched_readers);
    w.fixedField("matched_after_s", matched_after_s, 3).field("written", written);
    w.fixedField("writers_matched_after_s", writers_matched_after_s, 3).key("listen").raw(listen_json);
    w.field("error", error);
    std::printf("%s\n", w.endObject().str().c_str());
  } else {
    std::printf("mft-inject: domain %d, identity %s: participant %s\n", o.domain,
                o.security.enabled() ? o.security.identity.c_str() : "(none)", participant_status.c_str());
    if (!o.publish_topic.empty())
      std::printf("  publish %s (%s%s): writer %s, matched readers %d, written %llu\n", o.publish_topic.c_str(),
                  o.value.c_str(), o.follow ? ", follow" : "", writer_status.c_str(), matched_readers, written);
    std::fputs(listen_text.c_str(), stdout);
    if (!error.empty()) std::printf("  error: %s\n", error.c_str());
  }
  std::fflush(stdout);
}

}  // namespace mft::inject
