// Testbench for fp_sub_e7m16: streams 1000 vectors from a file, one per clock.
// Lint waivers: the file is named after the unit, not `tb`; counters and the clock use
// blocking assignments on purpose (testbench code, read back in the same step).
/* verilator lint_off DECLFILENAME */
/* verilator lint_off BLKSEQ */
`timescale 1ns/1ps
module tb;
    reg clock = 1'b0;
    reg in_valid = 1'b0;
    reg [23:0] a = 24'd0;
    reg [23:0] b = 24'd0;
    integer vectors;
    integer sent = 0;
    integer scanned;
    integer cycles = 0;
    reg [23:0] word_a;
    reg [23:0] word_b;
    wire out_valid_0;
    wire [23:0] result_0;
    integer results_0;
    integer received_0 = 0;
    fp_sub_e7m16 dut_0(.clock(clock), .in_valid(in_valid), .a(a), .b(b),
        .out_valid(out_valid_0), .result(result_0));

    always #5 clock = ~clock;

    initial begin
        vectors = $fopen("vectors.hex", "r");
        if (vectors == 0) begin
            $display("tb: cannot open vectors.hex");
            $finish;
        end
        results_0 = $fopen("results.hex", "w");
        if (results_0 == 0) begin
            $display("tb: cannot open results.hex");
            $finish;
        end
    end

    // Inputs change and outputs are sampled on the falling edge, away from the rising edge
    // where the units' registers load.
    always @(negedge clock) begin
        cycles = cycles + 1;
        if (out_valid_0) begin
            $fwrite(results_0, "%h\n", result_0);
            received_0 = received_0 + 1;
            if (received_0 == 1000) $fclose(results_0);
        end
        if (received_0 == 1000) begin
            $finish;
        end
        if (sent < 1000) begin
            scanned = $fscanf(vectors, "%h %h\n", word_a, word_b);
            if (scanned != 2) begin
                $display("tb: vectors.hex: vector %0d is not two hex words", sent + 1);
                $finish;
            end
            a <= word_a;
            b <= word_b;
            in_valid <= 1'b1;
            sent = sent + 1;
        end else begin
            in_valid <= 1'b0;
        end
        if (cycles > 1108) begin
            $display("tb: timeout after %0d clocks", cycles);
            $finish;
        end
    end
endmodule
