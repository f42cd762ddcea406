// A loopback HTTP server inside the test process that stands in for a language model: it
// answers each request with the next scripted response (OpenAI Chat Completions shapes) and
// keeps what it received. Used by the generation tests and the viewer's worker tests.
#pragma once

#include "scene/json_writer.h"

#include <httplib.h>

#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <deque>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace sdfcsg::test {

struct Scripted {
    int status = 200;
    std::string body;
    std::string retryAfter;
    bool hang = false; // answer only once the test releases the server
    bool echo = false; // "$AUTHORIZATION" in the body becomes the request's Authorization header
};

struct Received {
    std::string path;
    std::string body;
    httplib::Headers headers;
};

class FakeServer {
  public:
    // Requests to it set LlmConfig::proxy to "", so that no proxy from the environment stands
    // between the client and the loopback.
    FakeServer() {
        server_.Post(".*", [this](const httplib::Request& req, httplib::Response& res) {
            Scripted next{500, R"({"error": {"message": "no scripted response left"}})"};
            {
                std::unique_lock lock(mutex_);
                received_.push_back({req.path, req.body, req.headers});
                arrived_.notify_all();
                if (!script_.empty()) {
                    next = script_.front();
                    script_.pop_front();
                }
                if (next.hang)
                    released_.wait_for(lock, std::chrono::seconds(20), [this] { return release_; });
            }
            if (next.echo) {
                const std::string value = req.get_header_value("Authorization");
                for (size_t at = 0;
                     (at = next.body.find("$AUTHORIZATION", at)) != std::string::npos;
                     at += value.size())
                    next.body.replace(at, 14, value);
            }
            res.status = next.status;
            if (!next.retryAfter.empty()) res.set_header("Retry-After", next.retryAfter);
            res.set_content(next.body, "application/json");
        });
        port_ = server_.bind_to_any_port("127.0.0.1");
        thread_ = std::thread([this] { server_.listen_after_bind(); });
        while (!server_.is_running())
            std::this_thread::sleep_for(std::chrono::milliseconds(1));
    }
    ~FakeServer() {
        release();
        server_.stop();
        thread_.join();
    }
    void script(std::vector<Scripted> responses) {
        std::lock_guard lock(mutex_);
        script_.assign(responses.begin(), responses.end());
    }
    void release() {
        std::lock_guard lock(mutex_);
        release_ = true;
        released_.notify_all();
    }
    // Waits until `count` requests have arrived; false if they have not within `timeout`.
    bool awaitRequests(size_t count, std::chrono::seconds timeout = std::chrono::seconds(20)) {
        std::unique_lock lock(mutex_);
        return arrived_.wait_for(lock, timeout, [&] { return received_.size() >= count; });
    }
    std::vector<Received> received() {
        std::lock_guard lock(mutex_);
        return received_;
    }
    std::string url(const std::string& path = "/v1") const {
        return "http://127.0.0.1:" + std::to_string(port_) + path;
    }

  private:
    httplib::Server server_;
    std::thread thread_;
    int port_ = 0;
    std::mutex mutex_;
    std::condition_variable released_, arrived_;
    bool release_ = false;
    std::deque<Scripted> script_;
    std::vector<Received> received_;
};

// An OpenAI Chat Completions answer.
inline Scripted openAi(const std::string& content, const std::string& finish = "stop") {
    return {200, R"({"id": "x", "object": "chat.completion", "choices": [{"index": 0, "message":
        {"role": "assistant", "content": )" +
                     detail::jsonQuote(content) + R"(, "refusal": null}, "finish_reason": ")" +
                     finish + R"("}], "usage": {"prompt_tokens": 100, "completion_tokens": 20}})"};
}

} // namespace sdfcsg::test
