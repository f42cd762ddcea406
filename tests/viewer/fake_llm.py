# A stand-in for a language model endpoint, for the viewer's scripted generation test and the
# command line's Ctrl-C tests: every POST gets an OpenAI Chat Completions answer whose content is
# the file ANSWER, read anew for each request so the test can change it. With ANSWERED, only the
# first ANSWERED requests are answered and the next one is held for a minute, so that a client
# can be interrupted while it waits; PORT_FILE.held appears when a request is held. Writes the
# port it listens on to PORT_FILE.
# Usage: fake_llm.py ANSWER PORT_FILE [ANSWERED]
import http.server
import json
import os
import sys
import time

answer_path, port_path = sys.argv[1], sys.argv[2]
answered = int(sys.argv[3]) if len(sys.argv) > 3 else None
requests = 0


class Handler(http.server.BaseHTTPRequestHandler):
    def do_POST(self):
        global requests
        self.rfile.read(int(self.headers.get("Content-Length", 0)))
        requests += 1
        if answered is not None and requests > answered:
            open(port_path + ".held", "w").close()
            time.sleep(60)
            return
        with open(answer_path, encoding="utf-8") as f:
            content = f.read()
        body = json.dumps({
            "choices": [{"index": 0, "finish_reason": "stop",
                         "message": {"role": "assistant", "content": content}}],
            "usage": {"prompt_tokens": 1, "completion_tokens": 1},
        }).encode()
        self.send_response(200)
        self.send_header("Content-Type", "application/json")
        self.send_header("Content-Length", str(len(body)))
        self.end_headers()
        self.wfile.write(body)

    def log_message(self, *args):
        pass


server = http.server.HTTPServer(("127.0.0.1", 0), Handler)
with open(port_path + ".tmp", "w") as f:
    f.write(str(server.server_port))
# Renamed into place, so a reader never sees a half-written port.
os.replace(port_path + ".tmp", port_path)
server.serve_forever()
