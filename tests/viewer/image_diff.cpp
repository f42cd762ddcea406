// Compares two PNG images for the viewer tests.
//   image_diff A.png B.png same MAXDIFF MAXFRACTION  exit 0 when at most MAXFRACTION of the
//                                                    pixels differ by more than MAXDIFF (0..255)
//   image_diff A.png B.png differ MINFRACTION        exit 0 when at least MINFRACTION differ
//   image_diff A.png B.png within X0 Y0 X1 Y1 MARGIN MINFRACTION
//                                                    exit 0 when every differing pixel lies in
//                                                    [X0, X1) x [Y0, Y1) grown by MARGIN, and at
//                                                    least MINFRACTION of that rectangle differs
//   image_diff A.png B.png mask MAXDIFF MINFRACTION  exit 0 when the silhouettes agree on at
//                                                    least MINFRACTION of the pixels: a pixel
//                                                    is background when it is within MAXDIFF
//                                                    of A's top-left pixel (keep that corner
//                                                    empty), in both images or in neither
// Prints the sizes and the fraction of differing pixels either way; 1 when the check fails,
// 2 on bad arguments or unreadable files.
#define STB_IMAGE_IMPLEMENTATION
#define STB_IMAGE_STATIC
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wsign-compare"
#endif
#include <stb/stb_image.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>

int main(int argc, char** argv) {
    if (argc < 5) {
        std::fputs("usage: image_diff A.png B.png same MAXDIFF MAXFRACTION | differ MINFRACTION |"
                   " within X0 Y0 X1 Y1 MARGIN MINFRACTION | mask MAXDIFF MINFRACTION\n",
                   stderr);
        return 2;
    }
    std::string check = argv[3];
    int wa, ha, wb, hb, n;
    using Pixels = std::unique_ptr<unsigned char, decltype(&stbi_image_free)>;
    Pixels pa(stbi_load(argv[1], &wa, &ha, &n, 4), stbi_image_free);
    Pixels pb(stbi_load(argv[2], &wb, &hb, &n, 4), stbi_image_free);
    const unsigned char *a = pa.get(), *b = pb.get();
    if (!a || !b) {
        std::fprintf(stderr, "image_diff: cannot read %s\n", a ? argv[2] : argv[1]);
        return 2;
    }
    if (wa != wb || ha != hb) {
        std::printf("sizes differ: %dx%d and %dx%d\n", wa, ha, wb, hb);
        return 1;
    }
    if (check == "mask" && argc == 6) {
        // Shading differs between a ray-marched and a rasterised view; where the object is
        // must not.
        const int tolerance = std::atoi(argv[4]);
        auto background = [&](const unsigned char* image, long i) {
            for (int c = 0; c < 3; ++c)
                if (std::abs(int(image[4 * i + c]) - int(a[c])) > tolerance) return false;
            return true;
        };
        long disagree = 0;
        for (long i = 0; i < long(wa) * ha; ++i)
            disagree += background(a, i) != background(b, i);
        double agreement = 1.0 - double(disagree) / (double(wa) * ha);
        std::printf("%dx%d: the silhouettes agree on %.4f of the pixels\n", wa, ha, agreement);
        return agreement >= std::atof(argv[5]) ? 0 : 1;
    }
    int threshold = check == "same" ? std::atoi(argv[4]) : 8;
    long differing = 0, maxDiff = 0;
    int x0 = wa, y0 = ha, x1 = 0, y1 = 0; // the differing pixels' bounding rectangle
    for (long i = 0; i < long(wa) * ha; ++i) {
        int d = 0;
        for (int c = 0; c < 3; ++c)
            d = std::max(d, std::abs(int(a[4 * i + c]) - int(b[4 * i + c])));
        maxDiff = std::max<long>(maxDiff, d);
        if (d > threshold) {
            ++differing;
            int x = int(i % wa), y = int(i / wa);
            x0 = std::min(x0, x), y0 = std::min(y0, y);
            x1 = std::max(x1, x + 1), y1 = std::max(y1, y + 1);
        }
    }
    double fraction = double(differing) / (double(wa) * ha);
    std::printf("%dx%d: %.4f of the pixels differ by more than %d (largest difference %ld)\n", wa,
                ha, fraction, threshold, maxDiff);
    if (check == "within" && argc == 10) {
        int r[5];
        for (int k = 0; k < 5; ++k)
            r[k] = std::atoi(argv[4 + k]);
        const int m = r[4];
        std::printf(
            "differing pixels in [%d, %d) x [%d, %d), expected within [%d, %d) x [%d, %d)\n", x0,
            x1, y0, y1, r[0] - m, r[2] + m, r[1] - m, r[3] + m);
        double area = std::max(1.0, double(r[2] - r[0]) * double(r[3] - r[1]));
        bool inside = differing == 0 ||
                      (x0 >= r[0] - m && y0 >= r[1] - m && x1 <= r[2] + m && y1 <= r[3] + m);
        std::printf("%.3f of the rectangle differs\n", double(differing) / area);
        return inside && double(differing) / area >= std::atof(argv[9]) ? 0 : 1;
    }
    if (check == "same" && argc == 6) return fraction <= std::atof(argv[5]) ? 0 : 1;
    if (check == "differ") return fraction >= std::atof(argv[4]) ? 0 : 1;
    std::fputs("image_diff: expected \"same MAXDIFF MAXFRACTION\", \"differ MINFRACTION\", "
               "\"within X0 Y0 X1 Y1 MARGIN MINFRACTION\" or \"mask MAXDIFF MINFRACTION\"\n",
               stderr);
    return 2;
}
