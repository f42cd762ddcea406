// The Python module sdfcsg (docs/python.md): the modelling API of sdfcsg/model.h with Python
// operators and keyword arguments, a function for every kind of the node table (made from the
// table when the module loads), loading and saving scenes, and rendering, meshing and field
// evaluation into NumPy arrays on one Vulkan context per process.
#include <sdfcsg/points.h>
#include <sdfcsg/sdfcsg.h>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <Python.h>
#include <frameobject.h>

#include <algorithm>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <utility>
#include <vector>

namespace py = pybind11;
namespace m = sdfcsg::model;
using namespace sdfcsg;

namespace {

// sdfcsg.Error: the message is Error::str(), every diagnostic on its line ("file: path: what");
// `diagnostics` lists them as (file, path, message) and `kind` names the ErrorKind.
PyObject* errorType = nullptr;

[[noreturn]] void raise(const Error& error) {
    // A progress callback that saw Ctrl-C left KeyboardInterrupt set: that is what goes up.
    if (error.kind == ErrorKind::Cancelled && PyErr_Occurred()) throw py::error_already_set();
    static const char* const kinds[] = {"io",     "syntax", "validation", "limit",    "shader",
                                        "vulkan", "usage",  "remote",     "cancelled"};
    py::list diagnostics;
    for (const Diagnostic& d : error.diagnostics)
        diagnostics.append(py::make_tuple(d.file, d.path, d.message));
    py::object exception = py::reinterpret_borrow<py::object>(errorType)(error.str());
    exception.attr("diagnostics") = diagnostics;
    exception.attr("kind") = kinds[int(error.kind)];
    PyErr_SetObject(errorType, exception.ptr());
    throw py::error_already_set();
}

template <class T> T unwrap(Result<T> r) {
    if (!r) raise(r.error());
    return std::move(*r);
}

// "file:line" of the Python code that called into the module, for errors about what it made.
std::string caller() {
    PyFrameObject* frame = PyEval_GetFrame();
    if (!frame) return {};
    PyCodeObject* code = PyFrame_GetCode(frame);
    py::object file = py::reinterpret_steal<py::object>(
        PyObject_GetAttrString(reinterpret_cast<PyObject*>(code), "co_filename"));
    Py_DECREF(code);
    if (!file) {
        PyErr_Clear();
        return {};
    }
    return py::str(file).cast<std::string>() + ":" + std::to_string(PyFrame_GetLineNumber(frame));
}

m::Shape here(const m::Shape& shape) {
    m::ShapeData d = shape.data();
    d.origin = caller();
    return m::Shape(std::make_shared<const m::ShapeData>(std::move(d)));
}

// Whether NumPy is imported: the module imports it only to make an array, and a value cannot be
// one of its scalars before something has imported it.
bool numpyImported() {
    return py::module_::import("sys").attr("modules").contains("numpy");
}

bool isNumpyScalar(py::handle v) {
    return numpyImported() && py::isinstance(v, py::module_::import("numpy").attr("number"));
}

// Starts importing NumPy on a thread of its own, where nothing has imported it yet, for the
// device's work to hide: a first render's array then finds it imported, or nearly. Once.
void importNumpyMeanwhile() {
    static bool started = false;
    if (std::exchange(started, true) || numpyImported()) return;
    const py::cpp_function import([] {
        try {
            py::module_::import("numpy");
        } catch (py::error_already_set&) { // raised again where an array is made
        }
    });
    py::module_::import("threading")
        .attr("Thread")(py::arg("target") = import, py::arg("name") = "sdfcsg-numpy")
        .attr("start")();
}

// A Python value as a value of the scene format: numbers, strings, sequences (lists, tuples,
// NumPy arrays) and dicts of them; None is absent.
m::Value value(py::handle v) {
    if (v.is_none()) return {};
    if (py::isinstance<py::bool_>(v)) return m::Value::json(v.cast<bool>() ? "true" : "false");
    if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v) || isNumpyScalar(v))
        return m::Value(v.cast<double>());
    if (py::isinstance<py::str>(v)) return m::Value(v.cast<std::string>());
    if (py::isinstance<py::dict>(v)) { // a camera, a light
        std::string json = "{";
        for (auto [key, item] : v.cast<py::dict>()) {
            const m::Value member = value(item);
            json += (json.size() > 1 ? ", " : "") +
                    m::Value(py::str(key).cast<std::string>()).json() + ": " +
                    (member.absent() ? std::string("null") : member.json());
        }
        return m::Value::json(json + "}");
    }
    if (py::hasattr(v, "__len__") && py::hasattr(v, "__getitem__")) {
        std::string json = "[";
        for (size_t i = 0; i < py::len(v); ++i) {
            const m::Value item = value(v[py::int_(i)]);
            json += (i ? ", " : "") + (item.absent() ? std::string("null") : item.json());
        }
        return m::Value::json(json + "]");
    }
    throw py::type_error("sdfcsg: a value must be a number, a string or a sequence of them, not " +
                         py::str(py::type::of(v)).cast<std::string>());
}

glm::vec3 vec3(py::handle v) {
    if (py::isinstance<py::int_>(v) || py::isinstance<py::float_>(v))
        return glm::vec3(v.cast<float>());
    auto items = v.cast<std::vector<float>>();
    if (items.size() != 3) throw py::value_error("sdfcsg: expected 3 numbers [x, y, z]");
    return {items[0], items[1], items[2]};
}

// (x, y, z), ([x, y, z]) or (s) for translate, rotate and scale.
glm::vec3 vec3Args(const py::args& args, bool uniformAllowed) {
    if (args.size() == 3)
        return {args[0].cast<float>(), args[1].cast<float>(), args[2].cast<float>()};
    if (args.size() == 1 && (uniformAllowed || !(py::isinstance<py::int_>(args[0]) ||
                                                 py::isinstance<py::float_>(args[0]))))
        return vec3(args[0]);
    throw py::type_error("sdfcsg: expected x, y, z or [x, y, z]");
}

std::string signature(const KindInfo& kind) {
    std::string s = std::string(kind.name) + "(";
    if (kind.operation)
        s += isTransition(kind.kind)      ? "first, second, "
             : kind.role == Role::Boolean ? "*children, "
                                          : "child, ";
    for (const ParamInfo* p : positionalParams(kind))
        s += std::string(p->name) + (p->required ? "" : "=None") + ", ";
    s.resize(s.size() - 2);
    return s + ")";
}

std::string docstring(const KindInfo& kind) {
    std::string doc = signature(kind) + "\n\n" + std::string(kind.doc) + "\n";
    for (const ParamInfo* p : positionalParams(kind))
        doc += "\n" + std::string(p->name) + " (" + std::string(p->unit) +
               (p->required ? "" : ", optional") + "): " + std::string(p->doc);
    return doc;
}

// The node of kind `kind` from a Python call: its operands, then its parameters by position or
// keyword.
m::Shape build(const KindInfo& kind, py::args args, const py::kwargs& kwargs) {
    std::vector<m::Shape> children;
    size_t next = 0;
    if (kind.operation) {
        const size_t operands =
            kind.role == Role::Boolean && !isTransition(kind.kind)
                ? args.size()
                : std::min<size_t>(args.size(), isTransition(kind.kind) ? 2 : 1);
        for (; next < operands; ++next) {
            if (kind.role == Role::Boolean && !py::isinstance<m::Shape>(args[next]) &&
                py::isinstance<py::sequence>(args[next])) { // union([a, b])
                for (py::handle s : args[next])
                    children.push_back(s.cast<m::Shape>());
                continue;
            }
            if (!py::isinstance<m::Shape>(args[next])) break;
            children.push_back(args[next].cast<m::Shape>());
        }
    }
    const std::vector<const ParamInfo*> params = positionalParams(kind);
    if (args.size() - next > params.size())
        throw py::type_error("sdfcsg." + signature(kind) + ": too many arguments");
    std::vector<m::Arg> values;
    for (size_t i = next; i < args.size(); ++i)
        values.push_back({std::string(params[i - next]->name), value(args[i])});
    for (auto [key, v] : kwargs) {
        const std::string name = key.cast<std::string>();
        if (std::any_of(values.begin(), values.end(),
                        [&](const m::Arg& a) { return a.name == name; }))
            throw py::type_error("sdfcsg." + std::string(kind.name) + ": " + name + " given twice");
        values.push_back({name, value(v)});
    }
    return here(m::shape(kind.name, std::move(values), std::move(children)));
}

// The one Vulkan context of the process, made on first use, and the sampler of the last scene
// evaluated on it (members go in reverse order: the sampler before its context).
struct Device {
    std::unique_ptr<Context> context;
    std::string samplerScene; // the sampler's scene, as JSON
    std::unique_ptr<PointSampler> sampler;
};
Device& device() {
    static Device held;
    return held;
}
// The context, made on first use; without Python's lock held, so that other threads run meanwhile.
Result<Context*> sharedContext() {
    static std::mutex making;
    std::lock_guard lock(making);
    Device& d = device();
    if (!d.context) {
        auto made = Context::create();
        if (!made) return made.error();
        d.context = std::move(*made);
    }
    return d.context.get();
}
Context& context() {
    return *unwrap(sharedContext());
}

// A scene from a Shape or a Scene.
Scene sceneOf(py::handle object) {
    if (py::isinstance<m::Shape>(object)) return unwrap(m::toScene(object.cast<m::Shape>()));
    if (py::isinstance<Scene>(object)) return object.cast<Scene>();
    throw py::type_error("sdfcsg: expected a Shape or a Scene");
}

// A progress callback for long work: Ctrl-C stops it (the signal is seen between bands), and so
// does `progress(fraction)` returning False or raising; the error then raised is that exception
// or KeyboardInterrupt, left set for raise(). It takes Python's lock for each call, so that the
// work may run without it; the callable is held where copies of the callback need no lock.
std::function<bool(float)> interruptible(py::object progress = py::none()) {
    auto callable = std::make_shared<py::object>(std::move(progress));
    return [callable](float done) {
        py::gil_scoped_acquire lock;
        if (PyErr_CheckSignals() != 0) return false;
        if (callable->is_none()) return true;
        try {
            const py::object answer = (*callable)(done);
            return answer.is_none() || answer.cast<bool>();
        } catch (py::error_already_set& e) {
            e.restore();
            return false;
        }
    };
}

std::optional<Camera> cameraOf(const py::object& camera) {
    if (camera.is_none()) return std::nullopt;
    Camera c;
    const py::dict d = camera.cast<py::dict>();
    for (auto [key, v] : d) {
        const std::string k = key.cast<std::string>();
        if (k == "eye")
            c.eye = vec3(v);
        else if (k == "target")
            c.target = vec3(v);
        else if (k == "up")
            c.up = vec3(v);
        else if (k == "fov")
            c.fov = v.cast<float>();
        else
            throw py::value_error("sdfcsg: a camera has eye, target, up and fov, not " + k);
    }
    return c;
}

Image renderImage(py::handle object, uint32_t width, uint32_t height, const py::object& camera,
                  const std::string& mode, uint32_t aa, bool shadows, bool grid,
                  const py::object& progress = py::none()) {
    const Scene scene = sceneOf(object);
    RenderOptions options;
    options.width = width;
    options.height = height;
    auto parsedMode = parseRenderMode(mode);
    if (!parsedMode) throw py::value_error("sdfcsg: no render mode " + mode);
    options.mode = *parsedMode;
    options.camera = cameraOf(camera);
    options.aa = aa;
    options.shadows = shadows;
    options.grid = grid;
    options.progress = interruptible(progress);
    // The device's work runs without Python's lock, so that other threads run meanwhile (NumPy's
    // import, for render()'s array); `progress` takes it between bands.
    Image image = unwrap([&]() -> Result<Image> {
        py::gil_scoped_release release;
        auto context = sharedContext();
        if (!context) return context.error();
        auto renderer = Renderer::create(**context, scene);
        if (!renderer) return renderer.error();
        return (*renderer)->render(options);
    }());
    if (PyErr_Occurred()) throw py::error_already_set(); // raised by progress after the last band
    return image;
}

py::array_t<uint8_t> imageArray(const Image& image) {
    py::array_t<uint8_t> out({size_t(image.height), size_t(image.width), size_t(4)});
    std::copy(image.rgba.begin(), image.rgba.end(), out.mutable_data());
    return out;
}

template <class T, int N> py::array_t<T> rows(const void* data, size_t count) {
    py::array_t<T> out({count, size_t(N)});
    std::memcpy(out.mutable_data(), data, count * N * sizeof(T));
    return out;
}

// Points at or above this many go to the device where evaluate(device=None).
constexpr size_t kDeviceFrom = 1 << 16;

py::object evaluate(py::handle object,
                    py::array_t<float, py::array::c_style | py::array::forcecast> points,
                    bool colors, std::optional<bool> onDevice) {
    if (points.ndim() != 2 || points.shape(1) != 3)
        throw py::value_error("sdfcsg.evaluate: points must be an (N, 3) array");
    const size_t n = size_t(points.shape(0));
    const Scene scene = sceneOf(object);
    const auto* p = reinterpret_cast<const glm::vec3*>(points.data());
    py::array_t<float> distances(n);
    py::array_t<float> rgb({n, size_t(3)});
    float* d = distances.mutable_data();
    auto* c = reinterpret_cast<glm::vec3*>(rgb.mutable_data());
    if (onDevice.value_or(n >= kDeviceFrom)) {
        // The last scene's sampler is kept: evaluating one scene again compiles nothing.
        Device& held = device();
        std::string json = toJson(scene);
        if (!held.sampler || json != held.samplerScene) {
            held.sampler.reset();
            held.sampler = unwrap(PointSampler::create(context(), scene));
            held.samplerScene = std::move(json);
        }
        PointSampler* sampler = held.sampler.get();
        Status ok = Ok{};
        {
            py::gil_scoped_release release;
            ok = sampler->sample({p, n}, {d, n},
                                 colors ? std::span<glm::vec3>(c, n) : std::span<glm::vec3>());
        }
        if (!ok) raise(ok.error());
    } else {
        const Evaluator evaluator(scene);
        py::gil_scoped_release release;
        const size_t threads = std::clamp<size_t>(std::thread::hardware_concurrency(), 1,
                                                  std::max<size_t>(1, n / 4096));
        std::vector<std::thread> workers;
        for (size_t t = 0; t < threads; ++t)
            workers.emplace_back([&, t] {
                for (size_t i = n * t / threads; i < n * (t + 1) / threads; ++i) {
                    const Sample s = evaluator.sample(p[i]);
                    d[i] = s.distance;
                    if (colors) c[i] = s.color;
                }
            });
        for (std::thread& w : workers)
            w.join();
    }
    if (colors) return py::make_tuple(distances, rgb);
    return distances;
}

} // namespace

PYBIND11_MODULE(sdfcsg, module) {
    // The kinds' docstrings open with their own signatures, from the table.
    py::options pyOptions;
    pyOptions.disable_function_signatures();
    module.doc() = "Constructive solid geometry on signed distance fields, computed with Vulkan "
                   "(docs/python.md).";
    module.attr("__version__") = std::to_string(SDFCSG_VERSION_MAJOR) + "." +
                                 std::to_string(SDFCSG_VERSION_MINOR) + "." +
                                 std::to_string(SDFCSG_VERSION_PATCH);
    errorType = PyErr_NewExceptionWithDoc(
        "sdfcsg.Error",
        "A problem with a scene, a value or the device: the message names the file (or the "
        "line of Python that made the node), the JSON path and what was expected.",
        PyExc_ValueError, nullptr);
    module.attr("Error") = py::handle(errorType);

    py::class_<Scene> sceneClass(module, "Scene",
                                 "A loaded or built scene: nodes, definitions, camera, lights.");
    py::class_<m::Shape> shapeClass(module, "Shape",
                                    "A node and its subtree; immutable, cheap to copy.");
    shapeClass.def(py::init<>())
        .def("__or__", [](const m::Shape& a, const m::Shape& b) { return here(a | b); })
        .def("__and__", [](const m::Shape& a, const m::Shape& b) { return here(a & b); })
        .def("__sub__", [](const m::Shape& a, const m::Shape& b) { return here(a - b); })
        .def(
            "translate",
            [](const m::Shape& s, py::args a) { return s.translate(vec3Args(a, false)); },
            "translate(x, y, z) or translate([x, y, z]): moved, after what it has.")
        .def(
            "rotate", [](const m::Shape& s, py::args a) { return s.rotate(vec3Args(a, false)); },
            "rotate(x, y, z): turned about x, then y, then z, in degrees, after what it has.")
        .def(
            "scale", [](const m::Shape& s, py::args a) { return s.scale(vec3Args(a, true)); },
            "scale(s) or scale(x, y, z): scaled about the origin, after what it has.")
        .def(
            "color", [](const m::Shape& s, py::object c) { return s.color(value(c)); },
            "color([r, g, b]) in 0..1 or color('#rrggbb').")
        .def("name", [](const m::Shape& s, std::string n) { return s.name(std::move(n)); })
        .def(
            "set",
            [](const m::Shape& s, std::string key, py::object v) { return s.set(key, value(v)); },
            "set(parameter, value): one parameter by its JSON name.")
        .def(
            "json", [](const m::Shape& s) { return unwrap(m::toJson(s)); },
            "The scene's JSON text (raises sdfcsg.Error where a value is wrong).")
        .def("scene", [](const m::Shape& s) { return unwrap(m::toScene(s)); })
        .def("_repr_png_",
             [](const m::Shape& s) {
                 const Image image =
                     renderImage(py::cast(s), 400, 300, py::none(), "shaded", 2, true, false);
                 return py::bytes(unwrap(encodePng(image, "shape.png")));
             })
        .def("__repr__", [](const m::Shape& s) {
            const m::ShapeData& d = s.data();
            return "<sdfcsg.Shape " + d.type + (d.name.empty() ? "" : " \"" + d.name + "\"") +
                   (d.children.empty() ? "" : " of " + std::to_string(d.children.size())) + ">";
        });

    module.def(
        "shape",
        [](std::string type, const py::kwargs& kwargs) {
            std::vector<m::Arg> values;
            std::vector<m::Shape> children;
            for (auto [key, v] : kwargs) {
                const std::string name = key.cast<std::string>();
                if (name == "children")
                    children = v.cast<std::vector<m::Shape>>();
                else
                    values.push_back({name, value(v)});
            }
            return here(m::shape(type, std::move(values), std::move(children)));
        },
        "shape(type, children=[...], **parameters): a node of any kind by its JSON name.");

    py::class_<m::Part>(module, "Part",
                        "Part(name, node, **parameters): a definition, whose node may use "
                        "'$name' values; calling it makes a use.")
        .def(py::init([](std::string name, m::Shape node, const py::kwargs& kwargs) {
            std::vector<m::Arg> parameters;
            for (auto [key, v] : kwargs)
                parameters.push_back({key.cast<std::string>(), value(v)});
            return m::Part(std::move(name), std::move(node), std::move(parameters));
        }))
        .def("__call__", [](const m::Part& part, const py::kwargs& kwargs) {
            std::vector<m::Arg> arguments;
            for (auto [key, v] : kwargs)
                arguments.push_back({key.cast<std::string>(), value(v)});
            return here(part(std::move(arguments)));
        });

    sceneClass.def("json", [](const Scene& s) { return toJson(s); })
        .def(
            "python",
            [](const Scene& s, std::string_view output) { return m::toPython(s, output); },
            py::arg("output") = "scene.json",
            "python(output='scene.json'): the scene as a Python program that builds it with this "
            "module and saves it to its first argument, else to output.")
        .def("shape", [](const Scene& s) { return m::fromScene(s); })
        .def(
            "find", [](const Scene& s, std::string_view n) { return unwrap(m::findNode(s, n)); },
            "find(name_or_path): the index of a node.")
        .def(
            "set",
            [](Scene& s, py::object node, std::string key, py::object v) {
                const uint32_t index = py::isinstance<py::str>(node)
                                           ? unwrap(m::findNode(s, node.cast<std::string>()))
                                           : node.cast<uint32_t>();
                if (auto ok = m::setValue(s, index, key, value(v)); !ok) raise(ok.error());
            },
            "set(node, key, value): a node (by index, name or path) gets a new value, through "
            "the loader's checks.")
        .def_property_readonly("node_count", [](const Scene& s) { return s.nodes.size(); })
        .def("__repr__", [](const Scene& s) {
            return "<sdfcsg.Scene " + (s.file.empty() ? "" : s.file + " ") + "of " +
                   std::to_string(s.nodes.size()) + " nodes>";
        });

    module.def(
        "scene",
        [](const m::Shape& root, const py::kwargs& kwargs) {
            m::ShapeData d = root.data();
            std::vector<m::Arg> settings;
            for (auto [key, v] : kwargs) {
                const std::string name = key.cast<std::string>();
                if (name != "parts") {
                    settings.push_back({name, value(v)});
                    continue;
                }
                for (py::handle part : v)
                    d.parts.push_back(std::make_shared<const m::Part>(part.cast<m::Part>()));
            }
            return unwrap(
                m::toScene(m::Shape(std::make_shared<const m::ShapeData>(std::move(d))), settings));
        },
        "scene(root, name=None, description=None, camera=None, lights=None, background=None, "
        "parts=None) -> Scene: a shape's scene with the settings of the file's top level "
        "(camera and each light a dict; background a colour) and parts its uses need not "
        "reach, in this order.");
    module.def(
        "load", [](std::string path) { return unwrap(loadScene(path)); },
        "load(path): a scene file (raises sdfcsg.Error with the file and JSON path).");
    module.def(
        "loads",
        [](std::string_view json, std::string_view file) { return unwrap(parseScene(json, file)); },
        py::arg("json"), py::arg("file") = "<input>", "loads(json): a scene from text.");
    module.def(
        "save",
        [](py::handle object, std::string path) {
            if (auto ok = writeFileAtomic(path, toJson(sceneOf(object))); !ok) raise(ok.error());
        },
        "save(shape_or_scene, path): writes the scene's JSON.");

    module.def(
        "render",
        [](py::handle object, uint32_t width, uint32_t height, py::object camera, std::string mode,
           uint32_t aa, bool shadows, bool grid, py::object progress) {
            importNumpyMeanwhile();
            return imageArray(
                renderImage(object, width, height, camera, mode, aa, shadows, grid, progress));
        },
        py::arg("shape"), py::arg("width") = 800, py::arg("height") = 600,
        py::arg("camera") = py::none(), py::arg("mode") = "shaded", py::arg("aa") = 1,
        py::arg("shadows") = true, py::arg("grid") = false, py::arg("progress") = py::none(),
        "render(shape_or_scene, width=800, height=600, camera=None, mode='shaded', aa=1, "
        "shadows=True, grid=False, progress=None) -> uint8 array (height, width, 4), RGBA.\n\n"
        "camera: {'eye': [x, y, z], 'target': ..., 'up': ..., 'fov': degrees}. progress: called "
        "with the fraction done; returning False stops the render (sdfcsg.Error, kind "
        "'cancelled').");

    py::class_<Mesh>(module, "Mesh", "A triangle mesh: vertices, faces, normals, colors.")
        .def_property_readonly("vertices",
                               [](const Mesh& mesh) {
                                   return rows<float, 3>(mesh.positions.data(), mesh.vertexCount());
                               })
        .def_property_readonly("normals",
                               [](const Mesh& mesh) {
                                   return rows<float, 3>(mesh.normals.data(), mesh.vertexCount());
                               })
        .def_property_readonly(
            "colors",
            [](const Mesh& mesh) { return rows<float, 3>(mesh.colors.data(), mesh.vertexCount()); })
        .def_property_readonly("faces",
                               [](const Mesh& mesh) {
                                   return rows<uint32_t, 3>(mesh.indices.data(),
                                                            mesh.triangleCount());
                               })
        .def(
            "save",
            [](const Mesh& mesh, std::string path) {
                auto format = meshFormatFromPath(path);
                if (!format)
                    raise(
                        Error::message(ErrorKind::Usage, path,
                                       "unknown mesh format: use .ply, .obj, .stl, .glb or .3mf"));
                if (auto ok = writeMesh(mesh, path, *format); !ok) raise(ok.error());
            },
            "save(path): PLY, OBJ, STL, glTF (.glb) or 3MF, by the extension.")
        .def("__repr__", [](const Mesh& mesh) {
            return "<sdfcsg.Mesh of " + std::to_string(mesh.vertexCount()) + " vertices, " +
                   std::to_string(mesh.triangleCount()) + " triangles>";
        });

    module.def(
        "mesh",
        [](py::handle object, uint32_t resolution, std::optional<float> voxelSize,
           std::string method, std::optional<float> simplify, py::object progress) {
            const Scene scene = sceneOf(object);
            MeshOptions options;
            options.resolution = resolution;
            options.voxelSize = voxelSize;
            if (method == "marching_cubes")
                options.method = MeshMethod::MarchingCubes;
            else if (method != "dual_contouring")
                throw py::value_error("sdfcsg.mesh: method is dual_contouring or marching_cubes");
            options.progress = interruptible(progress);
            const std::unique_ptr<Mesher> mesher = unwrap(Mesher::create(context(), scene));
            Mesh mesh = unwrap(mesher->extract(options));
            if (simplify) {
                SimplifyOptions s;
                s.maxError = *simplify;
                s.progress = interruptible(progress);
                mesh = unwrap(simplifyMesh(mesh, mesher->evaluator(), s));
            }
            if (PyErr_Occurred()) throw py::error_already_set(); // from progress at the end
            return mesh;
        },
        py::arg("shape"), py::arg("resolution") = 128, py::arg("voxel_size") = py::none(),
        py::arg("method") = "dual_contouring", py::arg("simplify") = py::none(),
        py::arg("progress") = py::none(),
        "mesh(shape_or_scene, resolution=128, voxel_size=None, method='dual_contouring', "
        "simplify=None, progress=None) -> Mesh.\n\nsimplify: the largest distance from the "
        "surface the simplified mesh may stray. progress: as render's.");

    module.def("evaluate", &evaluate, py::arg("shape"), py::arg("points"),
               py::arg("colors") = false, py::arg("device") = py::none(),
               "evaluate(shape_or_scene, points (N, 3) float32, colors=False, device=None) -> "
               "distances (N,) float32 [, colors (N, 3)]. On the device from 65536 points unless "
               "device says.");
    // The device goes before the interpreter does: at the process's exit, after it, the
    // drivers' own teardown may already have run.
    module.def("_release_device", [] {
        device().sampler.reset();
        device().context.reset();
    });
    py::module_::import("atexit").attr("register")(module.attr("_release_device"));
    module.def("device_name", [] { return context().deviceName(); });
    module.def("_validation_messages", [] { return context().validationMessageCount(); });
    // A function for every kind, and a method for every operation of one child, from the table;
    // last, so that a kind's name taken by one of the functions above is seen.
    for (const KindInfo& kind : nodeKinds()) {
        const KindInfo* k = &kind;
        // The name that toPython writes: a kind named as one of the functions above takes a
        // trailing underscore, and a name it does not know to be taken stops the import.
        const std::string name = m::pythonName(kind);
        const bool method = kind.role == Role::Value || kind.role == Role::Domain;
        if (py::hasattr(module, name.c_str()) || (method && py::hasattr(shapeClass, name.c_str())))
            throw std::logic_error("sdfcsg: the kind " + std::string(kind.name) +
                                   " would be named " + name +
                                   ", which is taken: name it in pythonName (python_writer.cpp)");
        module.def(
            name.c_str(),
            [k](py::args args, const py::kwargs& kwargs) { return build(*k, args, kwargs); },
            docstring(kind).c_str());
        if (method)
            shapeClass.def(
                name.c_str(),
                [k](py::args args, const py::kwargs& kwargs) { return build(*k, args, kwargs); },
                docstring(kind).c_str());
    }
}
